// OctoPrint's /api/job (the current or selected file with its analysis, progress, start, cancel,
// pause, restart) and /api/connection (the default printer's link: state, port, baud rate,
// profile; connect and disconnect), with OctoPrint's shapes and status codes.
#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "server/api/api_json.hpp"
#include "server/api/octoprint_files.hpp"
#include "server/api/octoprint_routes.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

// The last finished print of `path` on the printer: its duration in seconds.
json last_print_time(Store& store, const Printer& printer, const std::string& path) {
  for (const PrintRecord& p : PrintStore(store.db()).list(printer.id(), 200))
    if (!p.job_id && p.filename == path && p.state == PrintState::finished && p.finished_at)
      return *p.finished_at - p.started_at;
  return nullptr;
}

json job_json(const OctoContext& ctx, const HttpRequest& r, const Printer& printer, const PrinterStatus& s) {
  json file = {{"name", nullptr},   {"path", nullptr}, {"display", nullptr},
               {"origin", nullptr}, {"size", nullptr}, {"date", nullptr}};
  json job = {{"file", nullptr},
              {"estimatedPrintTime", nullptr},
              {"lastPrintTime", nullptr},
              {"filament", nullptr},
              {"user", nullptr}};
  std::string path;
  const json progress = progress_json(s);  // as the push socket's: filepos in bytes; 100 % after a print
  if (s.print) {
    path = s.print->record.filename;
  } else {
    std::lock_guard lock(ctx.octo.mutex);
    path = ctx.octo.selected;
  }
  if (!path.empty()) {
    file["name"] = file["display"] = leaf_name(path);
    file["path"] = path;
    file["origin"] = "local";
    if (const auto f = PrintStore(ctx.store.db()).file(path)) {
      file["size"] = f->size, file["date"] = static_cast<long long>(f->uploaded_at);
      const json analysed = file_json_analysed(*f, r, ctx.store, ctx.printers, ctx.octo);
      if (const auto a = analysed.find("gcodeAnalysis"); a != analysed.end()) {
        job["estimatedPrintTime"] = a->value("estimatedPrintTime", json());
        job["filament"] = a->value("filament", json());
      }
    }
    job["lastPrintTime"] = last_print_time(ctx.store, printer, path);
  }
  job["file"] = file;
  json out = {{"job", job}, {"progress", progress}, {"state", state_text(s)}};
  if (s.state == PrinterState::error) out["error"] = s.error;
  return out;
}

// OctoPrint's restart: only a paused print, which starts again from its first line. Ours cancels
// it (heaters and motion as a cancel leaves them), waits for the printer to be idle, and prints
// the same file again.
void restart(const OctoContext& ctx, Printer& printer) {
  const PrinterStatus s = printer.status();
  if (s.state != PrinterState::paused || !s.print)
    throw ApiError(409, "not_paused", "the printer has no paused print to restart");
  const PrintRecord record = s.print->record;
  printer.cancel();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (printer.state() != PrinterState::operational) {
    if (std::chrono::steady_clock::now() > deadline || !connected(printer.state()))
      throw ApiError(409, "not_operational",
                     "the paused print was cancelled but the printer did not become idle");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (record.job_id)
    ctx.printers.print_job(printer, *record.job_id);
  else
    ctx.printers.print_file(printer, record.filename);
}

HttpResponse job_command(const OctoContext& ctx, const HttpRequest& r) {
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);
  Printer& printer = default_printer(ctx.printers);
  const std::string command = string_field(body, "command", "");
  if (command == "start") {
    std::string name;
    {
      std::lock_guard lock(ctx.octo.mutex);
      name = ctx.octo.selected;
    }
    if (name.empty()) throw ApiError(409, "no_file", "no file is selected: upload one with select=true");
    ctx.printers.print_file(printer, name);
  } else if (command == "restart") {
    restart(ctx, printer);
  } else if (command == "cancel") {
    printer.cancel();
  } else if (command == "pause") {
    // As OctoPrint documents it: pausing a paused print or resuming a printing one does nothing
    // (204); only without a print is it a conflict (409, from pause() or resume()).
    const std::string action = string_field(body, "action", "toggle");
    if (action != "pause" && action != "resume" && action != "toggle")
      throw ApiError(400, "bad_request", "'action' must be pause, resume or toggle");
    const PrinterState state = printer.state();
    if (action == "pause" || (action == "toggle" && state == PrinterState::printing)) {
      if (state != PrinterState::paused) printer.pause();
    } else if (action == "toggle" || state != PrinterState::printing) {
      printer.resume();
    }
  } else {
    throw ApiError(400, "bad_request", "'command' must be start, restart, cancel or pause");
  }
  return HttpResponse::text(204, "");
}

// The port OctoPrint would show: the device, or OctoPrint's name for its virtual printer.
std::string port_of(const PrinterConfig& c) {
  return c.kind == PrinterKind::sim ? "VIRTUAL" : c.port;
}

json connection_json(const OctoContext& ctx) {
  const Printer& printer = default_printer(ctx.printers);
  const PrinterConfig& c = printer.config();
  const PrinterState state = printer.state();
  const bool closed = state == PrinterState::disconnected;
  json baudrates = {250000, 230400, 115200, 57600, 38400, 19200, 9600};
  if (std::find(baudrates.begin(), baudrates.end(), json(c.baud)) == baudrates.end())
    baudrates.push_back(c.baud);
  json profiles = json::array();
  for (const auto& p : ctx.printers.all()) profiles.push_back({{"id", p->id()}, {"name", p->id()}});
  return {{"current",
           {{"state", closed ? std::string("Closed") : state_text(printer.status())},
            {"port", closed ? json(nullptr) : json(port_of(c))},
            {"baudrate", closed ? json(nullptr) : json(c.baud)},
            {"printerProfile", printer.id()}}},
          {"options",
           {{"ports", {port_of(c)}},
            {"baudrates", baudrates},
            {"printerProfiles", profiles},
            {"portPreference", port_of(c)},
            {"baudratePreference", c.baud},
            {"printerProfilePreference", printer.id()},
            {"autoconnect", c.autoconnect}}}};
}

// connect: `port`, `baudrate` and `printerProfile` must be what /api/connection offers (400
// otherwise, as OctoPrint); a printer already connected stays so. disconnect: 409 while printing.
// fake_ack: accepted and nothing done — our link resends on its own when an "ok" is lost.
HttpResponse connection_command(const OctoContext& ctx, const HttpRequest& r) {
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);
  Printer& printer = default_printer(ctx.printers);
  const std::string command = string_field(body, "command", "");
  const json options = connection_json(ctx)["options"];
  if (command == "connect") {
    if (const auto port = body.find("port");
        port != body.end() && *port != "AUTO" &&
        std::find(options["ports"].begin(), options["ports"].end(), *port) == options["ports"].end())
      throw ApiError(400, "bad_request", "invalid port: " + port->dump());
    if (const auto baud = body.find("baudrate");
        baud != body.end() && *baud != 0 &&
        std::find(options["baudrates"].begin(), options["baudrates"].end(), *baud) ==
            options["baudrates"].end())
      throw ApiError(400, "bad_request", "invalid baudrate: " + baud->dump().substr(0, 40));
    if (const auto profile = body.find("printerProfile");
        profile != body.end() && (!profile->is_string() || profile->get<std::string>() != printer.id()))
      throw ApiError(400, "bad_request", "invalid printer profile: " + profile->dump().substr(0, 80));
    const PrinterState s = printer.state();
    if (s == PrinterState::disconnected || s == PrinterState::error)
      printer.connect();
    else if (busy_printing(s))
      throw ApiError(409, "printer_busy", "the printer is printing: it stays connected");
  } else if (command == "disconnect") {
    printer.disconnect();
  } else if (command != "fake_ack") {
    throw ApiError(400, "bad_request", "'command' must be connect, disconnect or fake_ack");
  }
  return HttpResponse::text(204, "");
}

}  // namespace

void add_octoprint_job_routes(Router& router, const OctoContext& ctx) {
  router.add("GET", "/api/job", Access::key, [ctx](const HttpRequest& r, const PathParams&) {
    Printer& printer = default_printer(ctx.printers);
    return json_response(200, job_json(ctx, r, printer, printer.status()));
  });
  router.add("POST", "/api/job", Access::key,
             [ctx](const HttpRequest& r, const PathParams&) { return job_command(ctx, r); });
  router.add("GET", "/api/connection", Access::key, [ctx](const HttpRequest&, const PathParams&) {
    return json_response(200, connection_json(ctx));
  });
  router.add("POST", "/api/connection", Access::key,
             [ctx](const HttpRequest& r, const PathParams&) { return connection_command(ctx, r); });
}

}  // namespace salient::server
