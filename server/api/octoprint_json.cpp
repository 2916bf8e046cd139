#include "server/api/octoprint_json.hpp"

#include <cmath>
#include <optional>

#include "core/common/input_error.hpp"
#include "core/gcode/time_estimator.hpp"
#include "core/printer/printer_profile.hpp"
#include "server/api/api_json.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

// The first printer's profile, for what a file alone does not say (filament diameter, limits).
core::PrinterProfile first_profile(PrinterService& printers) {
  const Printer* p = printers.first();
  return p ? core::builtin_printer(p->config().profile).value_or(core::PrinterProfile{})
           : core::PrinterProfile{};
}

// OctoPrint's gcodeAnalysis (what its analysis queue stores with a file and FDM Monster, OctoPod
// and Cura show): estimatedPrintTime (s), filament.tool0 length (mm) and volume (cm³), and the
// printing area and its dimensions (mm), from our estimator. Limits the file sets (ours always
// do) override the profile's. nullopt for a file that cannot be read or is not G-code: OctoPrint
// then lists the file without one.
std::optional<json> analyse_file(Store& store, const StoredFile& f, const core::PrinterProfile& profile) {
  core::GcodeEstimate e;
  try {
    core::MachineLimits limits;
    limits.acceleration = limits.travel_acceleration = limits.retract_acceleration = profile.acceleration;
    limits.jerk[0] = limits.jerk[1] = profile.jerk;
    e = core::estimate_gcode(store.files().read(f.digest), f.name, limits);
  } catch (const core::InputError&) {
    return std::nullopt;
  } catch (const StoreError&) {
    return std::nullopt;
  }
  const double area = M_PI * profile.filament_diameter * profile.filament_diameter / 4;
  json out = {
      {"estimatedPrintTime", e.seconds},
      {"filament", {{"tool0", {{"length", e.filament_mm}, {"volume", e.filament_mm * area / 1000}}}}}};
  if (e.printed) {
    const double* lo = e.printing_min;
    const double* hi = e.printing_max;
    out["printingArea"] = {{"minX", lo[0]}, {"maxX", hi[0]}, {"minY", lo[1]},
                           {"maxY", hi[1]}, {"minZ", lo[2]}, {"maxZ", hi[2]}};
    out["dimensions"] = {{"width", hi[0] - lo[0]}, {"depth", hi[1] - lo[1]}, {"height", hi[2] - lo[2]}};
  }
  return out;
}

}  // namespace

bool is_gcode(const std::string& name) {
  const std::size_t dot = name.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string ext = name.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == "gcode" || ext == "gco" || ext == "g";
}

Printer& default_printer(PrinterService& printers) {
  if (Printer* p = printers.first()) return *p;
  throw ApiError(409, "not_operational", "no printer is configured");
}

// The URL the client used (behind a trusted proxy: its scheme, host and prefix, as OctoPrint
// builds its refs from X-Forwarded-*/X-Script-Name).
std::string base_url(const HttpRequest& r) {
  const std::string host = r.header("host");
  return host.empty() ? std::string() : r.scheme + "://" + host + r.base_path;
}

json file_json(const StoredFile& f, const HttpRequest& r) {
  const std::string base = base_url(r);
  const std::string leaf =
      f.name.substr(f.name.find_last_of('/') == std::string::npos ? 0 : f.name.find_last_of('/') + 1);
  return {{"name", leaf},
          {"display", leaf},
          {"path", f.name},
          {"type", "machinecode"},
          {"typePath", {"machinecode", "gcode"}},
          {"origin", "local"},
          {"size", f.size},
          {"date", static_cast<long long>(f.uploaded_at)},
          {"hash", f.digest},
          {"refs",
           {{"resource", base + "/api/files/local/" + f.name},
            {"download", base + "/downloads/files/local/" + f.name}}}};
}

// file_json with the file's gcodeAnalysis, computed once per content.
json file_json_analysed(const StoredFile& f, const HttpRequest& r, Store& store, PrinterService& printers,
                        OctoState& octo) {
  json out = file_json(f, r);
  {
    std::lock_guard lock(octo.mutex);
    if (const auto it = octo.analyses.find(f.digest); it != octo.analyses.end()) {
      if (!it->second.is_null()) out["gcodeAnalysis"] = it->second;
      return out;
    }
  }
  const std::optional<json> analysis = analyse_file(store, f, first_profile(printers));
  std::lock_guard lock(octo.mutex);
  if (octo.analyses.size() >= OctoState::kMaxAnalyses) octo.analyses.clear();
  octo.analyses[f.digest] = analysis.value_or(json());
  if (analysis) out["gcodeAnalysis"] = *analysis;
  return out;
}

std::string state_text(const PrinterStatus& s) {
  switch (s.state) {
    case PrinterState::operational:
      return "Operational";
    case PrinterState::printing:
      return "Printing";
    case PrinterState::paused:
      return "Paused";
    case PrinterState::cancelling:
      return "Cancelling";
    case PrinterState::finishing:
      return "Finishing";
    case PrinterState::connecting:
      return "Connecting";
    case PrinterState::error:
      return "Error: " + s.error;
    case PrinterState::disconnected:
      break;
  }
  return "Offline";
}

std::string state_id(const PrinterStatus& s) {
  switch (s.state) {
    case PrinterState::operational:
      return "OPERATIONAL";
    case PrinterState::printing:
      return "PRINTING";
    case PrinterState::paused:
      return "PAUSED";
    case PrinterState::cancelling:
      return "CANCELLING";
    case PrinterState::finishing:
      return "FINISHING";
    case PrinterState::connecting:
      return "CONNECTING";
    case PrinterState::error:
      return "CLOSED_WITH_ERROR";
    case PrinterState::disconnected:
      break;
  }
  return "OFFLINE";
}

json state_json(const PrinterStatus& s) {
  const PrinterState st = s.state;
  const bool operational = busy_printing(st) || st == PrinterState::operational;
  return {{"text", state_text(s)},
          {"flags",
           {{"operational", operational},
            {"printing", busy_printing(st) && st != PrinterState::paused},
            {"paused", st == PrinterState::paused},
            {"pausing", false},
            {"cancelling", st == PrinterState::cancelling},
            {"resuming", false},
            {"finishing", st == PrinterState::finishing},
            {"sdReady", false},
            {"error", st == PrinterState::error},
            {"ready", st == PrinterState::operational},
            {"closedOrError", !operational}}},
          {"error", s.error}};
}

json temperature_json(const PrinterStatus& s) {
  return temperature_json(s, {});
}

json temperature_json(const PrinterStatus& s, const std::map<std::string, double>& offsets) {
  const auto one = [&offsets](const Temperature& t, const std::string& name) {
    const auto offset = offsets.find(name);
    return json{{"actual", t.actual ? json(*t.actual) : json(nullptr)},
                {"target", t.target ? json(*t.target) : json(nullptr)},
                {"offset", offset == offsets.end() ? 0.0 : offset->second}};
  };
  return {{"tool0", one(s.hotend, "tool0")}, {"bed", one(s.bed, "bed")}};
}

json temperature_history_json(const std::vector<TemperatureSample>& samples, std::size_t limit) {
  std::vector<const TemperatureSample*> kept;
  for (const TemperatureSample& s : samples)
    if (has_reading(s)) kept.push_back(&s);
  json out = json::array();
  for (std::size_t i = kept.size() > limit ? kept.size() - limit : 0; i < kept.size(); ++i)
    out.push_back(temperature_sample_json(*kept[i]));
  return out;
}

json folder_json(const std::string& path, const HttpRequest& r) {
  const std::string leaf =
      path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
  return {{"name", leaf},
          {"display", leaf},
          {"path", path},
          {"type", "folder"},
          {"typePath", {"folder"}},
          {"origin", "local"},
          {"refs", {{"resource", base_url(r) + "/api/files/local/" + path}}}};
}

json temperature_sample_json(const TemperatureSample& sample) {
  const auto one = [](const Temperature& t) {
    return json{{"actual", t.actual ? json(*t.actual) : json(nullptr)},
                {"target", t.target ? json(*t.target) : json(nullptr)}};
  };
  return {
      {"time", static_cast<long long>(sample.time)}, {"tool0", one(sample.hotend)}, {"bed", one(sample.bed)}};
}

bool has_reading(const TemperatureSample& sample) {
  return sample.hotend.actual || sample.bed.actual;
}

json print_job_json(const PrinterStatus& s, const std::string& selected,
                    const std::optional<StoredFile>& file, const json& analysis) {
  const std::string name = s.print ? s.print->record.filename : selected;
  json f = {{"name", nullptr},   {"path", nullptr}, {"display", nullptr},
            {"origin", nullptr}, {"size", nullptr}, {"date", nullptr}};
  if (!name.empty()) {
    const std::string leaf = name.substr(name.find_last_of('/') + 1);  // OctoPrint: name is the leaf
    f = {{"name", leaf},      {"path", name},    {"display", leaf},
         {"origin", "local"}, {"size", nullptr}, {"date", nullptr}};
    if (file && file->name == name)
      f["size"] = file->size, f["date"] = static_cast<long long>(file->uploaded_at);
    if (s.print && s.print->file_bytes > 0) f["size"] = s.print->file_bytes;
  }
  json estimated = nullptr, filament = nullptr;
  if (analysis.is_object()) {
    if (const auto it = analysis.find("estimatedPrintTime"); it != analysis.end()) estimated = *it;
    if (const auto it = analysis.find("filament"); it != analysis.end()) filament = *it;
  }
  json last = nullptr;  // the last print of this file that finished, as OctoPrint keeps it
  if (s.last_print && s.last_print->filename == name && s.last_print->state == PrintState::finished &&
      s.last_print->finished_at)
    last = *s.last_print->finished_at - s.last_print->started_at;
  return {{"file", f},
          {"estimatedPrintTime", estimated},
          {"lastPrintTime", last},
          {"filament", filament},
          {"user", nullptr}};
}

json progress_json(const PrinterStatus& s) {
  // After a print that ended well OctoPrint keeps its progress: 100 %, its time, none left.
  if (!s.print && s.last_print && s.last_print->state == PrintState::finished && s.last_print->finished_at)
    return {{"completion", 100.0},
            {"filepos", nullptr},
            {"printTime", static_cast<long long>(*s.last_print->finished_at - s.last_print->started_at)},
            {"printTimeLeft", 0},
            {"printTimeLeftOrigin", nullptr}};
  if (!s.print)
    return {{"completion", nullptr},
            {"filepos", nullptr},
            {"printTime", nullptr},
            {"printTimeLeft", nullptr},
            {"printTimeLeftOrigin", nullptr}};
  const PrinterStatus::Running& p = *s.print;
  const std::optional<double> eta = p.eta();
  // Completion in bytes, as OctoPrint's (the share of commands when the size is unknown).
  const double completion =
      p.file_bytes > 0 ? 100.0 * double(p.filepos) / double(p.file_bytes) : p.fraction() * 100;
  return {{"completion", completion},
          {"filepos", p.filepos},
          {"printTime", static_cast<long long>(p.elapsed)},
          {"printTimeLeft", eta ? json(static_cast<long long>(*eta)) : json(nullptr)},
          {"printTimeLeftOrigin", eta ? json("linear") : json(nullptr)}};
}

}  // namespace salient::server
