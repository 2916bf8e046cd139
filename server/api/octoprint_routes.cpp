// The OctoPrint-compatible surface that slicers' "send to OctoPrint" uses (PrusaSlicer, Cura),
// mapped onto the first configured printer: version/server/login/settings for the connection
// test, files/local for the upload (with select and print), job and printer for status, and
// printer/command. Only what those clients read is filled in, with OctoPrint's field names.
#include <cmath>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/common/input_error.hpp"
#include "core/gcode/time_estimator.hpp"
#include "core/printer/printer_profile.hpp"
#include "server/api/api_json.hpp"
#include "server/api/routes.hpp"
#include "server/http/multipart.hpp"
#include "server/printers/print_file.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

// What OctoPrint keeps between requests: the selected file, and the analyses of stored files by
// digest (content-addressed, so never stale; bounded, as files come and go).
struct OctoState {
  static constexpr std::size_t kMaxAnalyses = 1024;
  std::mutex mutex;
  std::string selected;
  std::map<std::string, json> analyses;
};

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

std::string base_url(const HttpRequest& r) {
  const std::string host = r.header("host");
  return host.empty() ? std::string() : "http://" + host;
}

json file_json(const StoredFile& f, const HttpRequest& r) {
  const std::string base = base_url(r);
  return {{"name", f.name},
          {"display", f.name},
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
    case PrinterState::connecting:
      return "Connecting";
    case PrinterState::error:
      return "Error: " + s.error;
    case PrinterState::disconnected:
      break;
  }
  return "Offline";
}

json state_json(const PrinterStatus& s) {
  const bool printing = s.state == PrinterState::printing, paused = s.state == PrinterState::paused,
             cancelling = s.state == PrinterState::cancelling;
  const bool operational = busy_printing(s.state) || s.state == PrinterState::operational;
  return {{"text", state_text(s)},
          {"flags",
           {{"operational", operational},
            {"printing", printing},
            {"paused", paused},
            {"pausing", false},
            {"cancelling", cancelling},
            {"resuming", false},
            {"finishing", false},
            {"sdReady", false},
            {"error", s.state == PrinterState::error},
            {"ready", s.state == PrinterState::operational},
            {"closedOrError", !operational}}}};
}

json temperature_json(const PrinterStatus& s) {
  const auto one = [](const Temperature& t) {
    return json{{"actual", t.actual ? json(*t.actual) : json(nullptr)},
                {"target", t.target ? json(*t.target) : json(nullptr)},
                {"offset", 0}};
  };
  return {{"tool0", one(s.hotend)}, {"bed", one(s.bed)}};
}

}  // namespace

void add_octoprint_routes(Router& router, Store& store, PrinterService& printers,
                          const DaemonConfig& config) {
  auto octo = std::make_shared<OctoState>();
  const std::size_t max_json = config.max_json_bytes, depth = static_cast<std::size_t>(config.max_json_depth);

  router.add("GET", "/api/server", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"version", "1.10.0"}, {"safemode", nullptr}});
  });
  // Passive login: OctoPrint answers with the user the key belongs to.
  router.add("POST", "/api/login", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"name", "_api"},
                               {"active", true},
                               {"admin", true},
                               {"user", true},
                               {"groups", {"admins", "users"}},
                               {"permissions", json::array()},
                               {"_is_external_client", false}});
  });
  router.add("GET", "/api/settings", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"api", {{"enabled", true}, {"allowCrossOrigin", false}}},
                               {"appearance", {{"name", "salient"}, {"color", "default"}}},
                               {"feature", {{"sdSupport", false}, {"temperatureGraph", true}}},
                               {"folder", {{"uploads", ""}}},
                               {"webcam", {{"webcamEnabled", false}, {"streamUrl", ""}}},
                               {"plugins", json::object()}});
  });
  router.add("GET", "/api/printerprofiles", Access::key, [&printers](const HttpRequest&, const PathParams&) {
    json profiles = json::object();
    for (const auto& p : printers.all()) {
      const auto profile = core::builtin_printer(p->config().profile);
      const core::PrinterProfile pp = profile.value_or(core::PrinterProfile{});
      profiles[p->id()] = {{"id", p->id()},
                           {"name", pp.name.empty() ? p->id() : pp.name},
                           {"model", pp.id},
                           {"default", p.get() == printers.first()},
                           {"current", p.get() == printers.first()},
                           {"heatedBed", pp.bed_temperature > 0},
                           {"heatedChamber", false},
                           {"volume",
                            {{"width", pp.bed_width},
                             {"depth", pp.bed_depth},
                             {"height", pp.max_height},
                             {"formFactor", "rectangular"},
                             {"origin", pp.origin_at_center ? "center" : "lowerleft"}}},
                           {"extruder", {{"count", 1}, {"nozzleDiameter", pp.nozzle_diameter}}}};
    }
    return json_response(200, {{"profiles", profiles}});
  });

  // The upload: multipart `file`, and optionally `path`, `select`, `print` (as PrusaSlicer and
  // Cura send them). 201 + Location; with print=true the first printer starts it (409 if busy).
  router.add(
      "POST", "/api/files/local", Access::key,
      [&store, &printers, octo](const HttpRequest& r, const PathParams&) {
        const auto boundary = multipart_boundary(r.header("content-type"));
        if (!boundary) throw ApiError(400, "bad_request", "send multipart/form-data with a 'file' part");
        std::vector<FormPart> parts;
        try {
          parts = parse_multipart(r.body, *boundary);
        } catch (const std::invalid_argument& e) {
          throw ApiError(400, "bad_request", e.what());
        }
        const FormPart* file = nullptr;
        bool select = false, print = false;
        for (const FormPart& p : parts) {
          if (p.name == "file" && p.filename) file = &p;
          if (p.name == "select") select = p.body == "true";
          if (p.name == "print") print = p.body == "true";
        }
        if (!file)
          throw ApiError(400, "bad_request", "the multipart body has no 'file' part with a filename");
        const std::string name = sanitize_filename(*file->filename);
        if (!is_gcode(name))
          throw ApiError(415, "unsupported_format",
                         name +
                             ": only G-code (.gcode, .gco, .g) can be uploaded here; "
                             "send models to /api/v1/jobs to slice them");
        check_printable(name, file->body);  // 422 now, not a print that stalls later
        std::optional<std::string> replaced;
        {
          std::lock_guard files_lock(store.files_mutex());  // the file and its row land together
          if (auto old = PrintStore(store.db()).file(name)) replaced = old->digest;
          const std::string digest = store.files().put(file->body);
          PrintStore(store.db())
              .put_file(
                  name, digest, static_cast<long long>(file->body.size()),
                  std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
        }
        if (replaced) store.remove_unreferenced({*replaced});  // an upload under the same name replaces it
        if (select || print) {
          std::lock_guard lock(octo->mutex);
          octo->selected = name;
        }
        if (print) printers.print_file(default_printer(printers), name);
        const StoredFile stored = *PrintStore(store.db()).file(name);
        const json f = file_json(stored, r);
        HttpResponse out = json_response(201, {{"files",
                                                {{"local",
                                                  {{"name", f["name"]},
                                                   {"display", f["display"]},
                                                   {"path", f["path"]},
                                                   {"origin", "local"},
                                                   {"refs", f["refs"]}}}}},
                                               {"done", true},
                                               {"effectiveSelect", select || print},
                                               {"effectivePrint", print}});
        out.headers.emplace_back("Location", f["refs"]["resource"].get<std::string>());
        return out;
      });
  const auto list_files = [&store, &printers, octo](const HttpRequest& r, const PathParams&) {
    json files = json::array();
    for (const StoredFile& f : PrintStore(store.db()).files())
      files.push_back(file_json_analysed(f, r, store, printers, *octo));
    return json_response(200, {{"files", files}, {"free", nullptr}});
  };
  router.add("GET", "/api/files", Access::key, list_files);
  router.add("GET", "/api/files/local", Access::key, list_files);
  router.add("GET", "/api/files/local/{name}", Access::key,
             [&store, &printers, octo](const HttpRequest& r, const PathParams& p) {
               const auto f = PrintStore(store.db()).file(p.at("name"));
               if (!f) throw ApiError(404, "not_found", "no file '" + p.at("name") + "'");
               return json_response(200, file_json_analysed(*f, r, store, printers, *octo));
             });
  router.add("DELETE", "/api/files/local/{name}", Access::key,
             [&store](const HttpRequest&, const PathParams& p) {
               const auto f = PrintStore(store.db()).file(p.at("name"));
               if (!f || !PrintStore(store.db()).remove_file(p.at("name")))
                 throw ApiError(404, "not_found", "no file '" + p.at("name") + "'");
               store.remove_unreferenced({f->digest});
               return HttpResponse::text(204, "");
             });
  router.add("GET", "/downloads/files/local/{name}", Access::key,
             [&store](const HttpRequest&, const PathParams& p) {
               const auto f = PrintStore(store.db()).file(p.at("name"));
               if (!f) throw ApiError(404, "not_found", "no file '" + p.at("name") + "'");
               return HttpResponse::text(200, store.files().read(f->digest), "text/x.gcode");
             });

  router.add(
      "GET", "/api/job", Access::key, [&printers, &store, octo](const HttpRequest&, const PathParams&) {
        const PrinterStatus s = default_printer(printers).status();
        json file = {
            {"name", nullptr}, {"path", nullptr}, {"origin", nullptr}, {"size", nullptr}, {"date", nullptr}};
        json progress = {{"completion", nullptr},
                         {"filepos", nullptr},
                         {"printTime", nullptr},
                         {"printTimeLeft", nullptr}};
        std::string name;
        if (s.print) {
          const PrinterStatus::Running& p = *s.print;
          const std::optional<double> eta = p.eta();
          name = p.record.filename;
          progress = {{"completion", p.fraction() * 100},
                      {"filepos", p.record.confirmed},
                      {"printTime", p.elapsed},
                      {"printTimeLeft", eta ? json(*eta) : json(nullptr)}};
        } else {
          std::lock_guard lock(octo->mutex);
          name = octo->selected;
        }
        if (!name.empty()) {
          file = {{"name", name}, {"path", name}, {"origin", "local"}, {"size", nullptr}, {"date", nullptr}};
          if (const auto f = PrintStore(store.db()).file(name))
            file["size"] = f->size, file["date"] = static_cast<long long>(f->uploaded_at);
        }
        return json_response(
            200, {{"job", {{"file", file}, {"estimatedPrintTime", nullptr}, {"filament", nullptr}}},
                  {"progress", progress},
                  {"state", state_text(s)}});
      });
  router.add("POST", "/api/job", Access::key,
             [&printers, octo, max_json, depth](const HttpRequest& r, const PathParams&) {
               const json body = parse_json_body(r, max_json, depth);
               Printer& printer = default_printer(printers);
               const std::string command = string_field(body, "command", "");
               if (command == "start") {
                 std::string name;
                 {
                   std::lock_guard lock(octo->mutex);
                   name = octo->selected;
                 }
                 if (name.empty())
                   throw ApiError(409, "no_file", "no file is selected: upload one with select=true");
                 printers.print_file(printer, name);
               } else if (command == "cancel") {
                 printer.cancel();
               } else if (command == "pause") {
                 const std::string action = string_field(body, "action", "toggle");
                 if (action == "pause" || (action == "toggle" && printer.state() == PrinterState::printing))
                   printer.pause();
                 else if (action == "resume" || action == "toggle")
                   printer.resume();
                 else
                   throw ApiError(400, "bad_request", "'action' must be pause, resume or toggle");
               } else {
                 throw ApiError(400, "bad_request", "'command' must be start, cancel or pause");
               }
               return HttpResponse::text(204, "");
             });
  router.add("GET", "/api/printer", Access::key, [&printers](const HttpRequest&, const PathParams&) {
    const PrinterStatus s = default_printer(printers).status();
    if (!connected(s.state)) throw ApiError(409, "not_operational", "Printer is not operational");
    return json_response(
        200, {{"temperature", temperature_json(s)}, {"sd", {{"ready", false}}}, {"state", state_json(s)}});
  });
  router.add("POST", "/api/printer/command", Access::key,
             [&printers, max_json, depth](const HttpRequest& r, const PathParams&) {
               default_printer(printers).command(parse_commands(parse_json_body(r, max_json, depth)));
               return HttpResponse::text(204, "");
             });
}

}  // namespace salient::server
