// The OctoPrint-compatible surface that slicers (PrusaSlicer, Cura), farm managers (FDM Monster)
// and phone apps (OctoPod) call, mapped onto the first configured printer, with OctoPrint's field
// names, status codes and error cases. This file: server, printer profiles, and the
// helpers the areas share; the areas are octoprint_{file,job,printer,system}_routes.cpp.
#include "server/api/octoprint_routes.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/common/input_error.hpp"
#include "core/gcode/time_estimator.hpp"
#include "core/printer/printer_profile.hpp"
#include "server/api/api_json.hpp"
#include "server/api/octoprint_files.hpp"
#include "server/api/octoprint_json.hpp"
#include "server/api/routes.hpp"
#include "server/api/sessions.hpp"
#include "server/build_info.hpp"
#include "server/http/multipart.hpp"
#include "server/printers/print_file.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

using nlohmann::json;

double octo_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool octo_file_busy(PrinterService& printers, const std::string& path) {
  for (const auto& p : printers.all()) {
    const PrinterStatus s = p->status();
    // A job's print is named after the job, not a stored file.
    if (s.print && !s.print->record.job_id && in_folder(path, s.print->record.filename)) return true;
  }
  return false;
}

json octo_print_or_queue(const OctoContext& ctx, const std::string& path) {
  const PrintSubmission sent = ctx.printers.submit_file(default_printer(ctx.printers), path);
  if (!sent.queued) return {{"effectivePrint", true}};
  return {{"effectivePrint", false},
          {"queued", {{"entry", sent.queued->id}, {"position", sent.queued->position}}}};
}

void add_octoprint_routes(Router& router, Store& store, PrinterService& printers, const DaemonConfig& config,
                          OctoState& octo_state, [[maybe_unused]] Sessions& sessions, EventHub& hub) {
  const std::size_t max_json = config.max_json_bytes, depth = static_cast<std::size_t>(config.max_json_depth);

  // The same OctoPrint version /api/version tells (build_info.hpp).
  router.add("GET", "/api/server", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"version", std::string(octoprint_version)}, {"safemode", nullptr}});
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
                           {"extruder", {{"count", 1}, {"nozzleDiameter", pp.nozzle_diameter}}},
                           // Jog feedrates (mm/min), OctoPrint's defaults; no axis inverted.
                           {"axes",
                            {{"x", {{"speed", 6000}, {"inverted", false}}},
                             {"y", {{"speed", 6000}, {"inverted", false}}},
                             {"z", {{"speed", 200}, {"inverted", false}}},
                             {"e", {{"speed", 300}, {"inverted", false}}}}}};
    }
    return json_response(200, {{"profiles", profiles}});
  });

  const OctoContext ctx{store, printers, config, octo_state, hub, max_json, depth};
  add_octoprint_file_routes(router, ctx);
  add_octoprint_job_routes(router, ctx);
  add_octoprint_printer_routes(router, ctx);
  add_octoprint_system_routes(router, ctx);
}

}  // namespace salient::server
