// What the OctoPrint route files share (included from them only): the objects every handler is
// given, and the helpers more than one area needs. add_octoprint_routes (routes.hpp) calls each
// area's add_… in turn.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "server/api/octoprint_json.hpp"
#include "server/api/routes.hpp"

namespace salient::server {

// References only: everything it names outlives the router.
struct OctoContext {
  Store& store;
  PrinterService& printers;
  const DaemonConfig& config;
  OctoState& octo;
  EventHub& hub;
  std::size_t max_json, depth;
};

// files/local…, downloads/files/local… (octoprint_file_routes.cpp).
void add_octoprint_file_routes(Router& router, const OctoContext& ctx);
// /api/job and /api/connection (octoprint_job_routes.cpp).
void add_octoprint_job_routes(Router& router, const OctoContext& ctx);
// /api/printer and its tool, bed, printhead, sd, chamber, command (octoprint_printer_routes.cpp).
void add_octoprint_printer_routes(Router& router, const OctoContext& ctx);
// /api/settings, /api/system/… (octoprint_system_routes.cpp).
void add_octoprint_system_routes(Router& router, const OctoContext& ctx);

double octo_now();
// Whether a printer is printing (or paused on) the stored file at `path`, or any file under the
// folder `path`.
bool octo_file_busy(PrinterService& printers, const std::string& path);
// A print of the stored file `path` on the default printer, or its place in the queue when the
// printer is busy: {"effectivePrint": bool, "queued": {"entry", "position"}} (queued only when
// it is). Conflict (409) when the printer is idle but cannot print (not connected).
nlohmann::json octo_print_or_queue(const OctoContext& ctx, const std::string& path);

}  // namespace salient::server
