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
#include "server/api/octoprint_json.hpp"
#include "server/api/routes.hpp"
#include "server/api/sessions.hpp"
#include "server/http/multipart.hpp"
#include "server/printers/print_file.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

using nlohmann::json;

void add_octoprint_routes(Router& router, Store& store, PrinterService& printers, const DaemonConfig& config,
                          OctoState& octo_state, [[maybe_unused]] Sessions& sessions) {
  OctoState* octo = &octo_state;
  const std::size_t max_json = config.max_json_bytes, depth = static_cast<std::size_t>(config.max_json_depth);

  router.add("GET", "/api/server", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"version", "1.10.0"}, {"safemode", nullptr}});
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
        octo->files_changed(name);                             // the push socket's FileAdded
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
             [&store, octo](const HttpRequest&, const PathParams& p) {
               const auto f = PrintStore(store.db()).file(p.at("name"));
               if (!f || !PrintStore(store.db()).remove_file(p.at("name")))
                 throw ApiError(404, "not_found", "no file '" + p.at("name") + "'");
               store.remove_unreferenced({f->digest});
               octo->files_changed();
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
          name = s.print->record.filename;
          progress = progress_json(s);  // as the push socket's: filepos in bytes
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
