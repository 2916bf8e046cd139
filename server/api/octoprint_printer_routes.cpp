// OctoPrint's /api/printer: the state with temperatures (and their history), and the controls
// farm managers and phone apps use — tool and bed targets and offsets, extrusion, flow and feed
// rates, jog and home — as G-code through Printer::command (409 when the printer cannot take it).
// No SD card (404, as OctoPrint with SD support off) and no heated chamber (409, as OctoPrint).
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "server/api/api_json.hpp"
#include "server/api/octoprint_printer_commands.hpp"
#include "server/api/octoprint_routes.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

core::PrinterProfile profile_of(const Printer& printer) {
  return core::builtin_printer(printer.config().profile).value_or(core::PrinterProfile{});
}

// 409 unless the printer's link is up (OctoPrint's is_operational, printing included).
PrinterStatus operational(Printer& printer) {
  PrinterStatus s = printer.status();
  if (!connected(s.state)) throw ApiError(409, "not_operational", "Printer is not operational");
  return s;
}

bool wants_history(const HttpRequest& r) {
  const auto it = r.query.find("history");
  return it != r.query.end() && (it->second == "true" || it->second == "1" || it->second == "yes");
}

// ?limit=N (digits only, as OctoPrint; else 300).
std::size_t history_limit(const HttpRequest& r) {
  const auto it = r.query.find("limit");
  if (it == r.query.end() || it->second.empty() || it->second.size() > 9 ||
      it->second.find_first_not_of("0123456789") != std::string::npos)
    return 300;
  return static_cast<std::size_t>(std::stoul(it->second));
}

// {tool0, bed} (and "history"), kept to `keep` ("" for both) as OctoPrint's _keep_tools/_keep_bed.
json temperatures(const OctoContext& ctx, const HttpRequest& r, const Printer& printer,
                  const PrinterStatus& s, const std::string& keep) {
  json out;
  {
    std::lock_guard lock(ctx.octo.mutex);
    out = temperature_json(s, ctx.octo.offsets);
  }
  if (wants_history(r))
    out["history"] = temperature_history_json(ctx.printers.temperatures(printer.id()).samples(octo_now()),
                                              history_limit(r));
  if (keep.empty()) return out;
  const std::string drop = keep == "tool0" ? "bed" : "tool0";
  out.erase(drop);
  if (out.contains("history"))
    for (json& h : out["history"]) h.erase(drop);
  return out;
}

json printer_state(const OctoContext& ctx, const HttpRequest& r) {
  Printer& printer = default_printer(ctx.printers);
  const PrinterStatus s = operational(printer);
  std::set<std::string> excluded;
  if (const auto it = r.query.find("exclude"); it != r.query.end()) {
    std::stringstream list(it->second);
    for (std::string item; std::getline(list, item, ',');) excluded.insert(item);
  }
  json out = json::object();
  if (!excluded.count("temperature")) out["temperature"] = temperatures(ctx, r, printer, s, "");
  if (!excluded.count("sd")) out["sd"] = {{"ready", false}};
  if (!excluded.count("state")) {
    out["state"] = state_json(s);
    out["state"]["error"] = s.state == PrinterState::error ? s.error : "";
  }
  return out;
}

std::string command_of(const json& body, const std::string& allowed) {
  const std::string command = string_field(body, "command", "");
  if (command.empty()) throw ApiError(400, "bad_request", "'command' is missing: one of " + allowed);
  return command;
}

const json& required(const json& body, const char* key, const std::string& command) {
  const auto it = body.find(key);
  if (it == body.end())
    throw ApiError(400, "bad_request",
                   "mandatory parameter '" + std::string(key) + "' of " + command + " is missing");
  return *it;
}

HttpResponse tool_command(const OctoContext& ctx, const HttpRequest& r) {
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);
  Printer& printer = default_printer(ctx.printers);
  const PrinterStatus s = operational(printer);
  const std::string command = command_of(body, "select, target, offset, extrude, flowrate");
  std::vector<std::string> gcode;
  if (command == "select") {
    gcode = tool_select_gcode(required(body, "tool", command));
  } else if (command == "target") {
    std::lock_guard lock(ctx.octo.mutex);
    gcode = tool_target_gcode(required(body, "targets", command), ctx.octo.offsets["tool0"]);
  } else if (command == "offset") {
    const json& offsets = required(body, "offsets", command);
    if (!offsets.is_object())
      throw ApiError(400, "bad_request", "'offsets' must be an object such as {\"tool0\": 5}");
    std::map<std::string, double> checked;
    for (const auto& [tool, value] : offsets.items()) {
      if (tool != "tool0") throw ApiError(400, "bad_request", "'offsets' may name tool0 only");
      checked[tool] = checked_offset(value, tool);
    }
    std::lock_guard lock(ctx.octo.mutex);
    for (const auto& [tool, value] : checked) ctx.octo.offsets[tool] = value;
    return HttpResponse::text(204, "");
  } else if (command == "extrude") {
    if (busy_printing(s.state)) throw ApiError(409, "printer_busy", "Printer is currently printing");
    required(body, "amount", command);
    gcode = extrude_gcode(body);
  } else if (command == "flowrate") {
    gcode = {flowrate_gcode(required(body, "factor", command))};
  } else {
    throw ApiError(400, "bad_request", "'command' must be select, target, offset, extrude or flowrate");
  }
  printer.command(gcode);
  return HttpResponse::text(204, "");
}

HttpResponse bed_command(const OctoContext& ctx, const HttpRequest& r) {
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);
  Printer& printer = default_printer(ctx.printers);
  operational(printer);
  if (profile_of(printer).bed_temperature <= 0)
    throw ApiError(409, "no_heated_bed", "Printer does not have a heated bed");
  const std::string command = command_of(body, "target, offset");
  if (command == "target") {
    std::vector<std::string> gcode;
    {
      std::lock_guard lock(ctx.octo.mutex);
      gcode = bed_target_gcode(required(body, "target", command), ctx.octo.offsets["bed"]);
    }
    printer.command(gcode);
  } else if (command == "offset") {
    const double offset = checked_offset(required(body, "offset", command), "bed");
    std::lock_guard lock(ctx.octo.mutex);
    ctx.octo.offsets["bed"] = offset;
  } else {
    throw ApiError(400, "bad_request", "'command' must be target or offset");
  }
  return HttpResponse::text(204, "");
}

HttpResponse printhead_command(const OctoContext& ctx, const HttpRequest& r) {
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);
  Printer& printer = default_printer(ctx.printers);
  const std::string command = command_of(body, "jog, home, feedrate");
  const PrinterStatus s = printer.status();
  if (!connected(s.state) || (busy_printing(s.state) && command != "feedrate"))
    throw ApiError(409, "not_operational", "Printer is not operational or currently printing");
  if (command == "jog") {
    if (const auto gcode = jog_gcode(body, profile_of(printer)); !gcode.empty()) printer.command(gcode);
  } else if (command == "home") {
    printer.command(home_gcode(body));
  } else if (command == "feedrate") {
    printer.command({feedrate_gcode(required(body, "factor", command))});
  } else {
    throw ApiError(400, "bad_request", "'command' must be jog, home or feedrate");
  }
  return HttpResponse::text(204, "");
}

}  // namespace

void add_octoprint_printer_routes(Router& router, const OctoContext& ctx) {
  router.add("GET", "/api/printer", Access::key, [ctx](const HttpRequest& r, const PathParams&) {
    return json_response(200, printer_state(ctx, r));
  });
  router.add("POST", "/api/printer/command", Access::key, [ctx](const HttpRequest& r, const PathParams&) {
    // As OctoPrint's: any command, a move during a print too ("should be used with some care").
    default_printer(ctx.printers).command(parse_commands(parse_json_body(r, ctx.max_json, ctx.depth)), true);
    return HttpResponse::text(204, "");
  });
  router.add("GET", "/api/printer/command/custom", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"controls", json::array()}});  // no custom controls configured
  });
  router.add("GET", "/api/printer/tool", Access::key, [ctx](const HttpRequest& r, const PathParams&) {
    Printer& printer = default_printer(ctx.printers);
    return json_response(200, temperatures(ctx, r, printer, operational(printer), "tool0"));
  });
  router.add("POST", "/api/printer/tool", Access::key,
             [ctx](const HttpRequest& r, const PathParams&) { return tool_command(ctx, r); });
  router.add("GET", "/api/printer/bed", Access::key, [ctx](const HttpRequest& r, const PathParams&) {
    Printer& printer = default_printer(ctx.printers);
    const PrinterStatus s = operational(printer);
    if (profile_of(printer).bed_temperature <= 0)
      throw ApiError(409, "no_heated_bed", "Printer does not have a heated bed");
    return json_response(200, temperatures(ctx, r, printer, s, "bed"));
  });
  router.add("POST", "/api/printer/bed", Access::key,
             [ctx](const HttpRequest& r, const PathParams&) { return bed_command(ctx, r); });
  router.add("POST", "/api/printer/printhead", Access::key,
             [ctx](const HttpRequest& r, const PathParams&) { return printhead_command(ctx, r); });
  for (const char* method : {"GET", "POST"}) {
    router.add(method, "/api/printer/sd", Access::key,
               [](const HttpRequest&, const PathParams&) -> HttpResponse {
                 throw ApiError(404, "not_found", "SD support is disabled");
               });
    router.add(method, "/api/printer/chamber", Access::key,
               [ctx](const HttpRequest&, const PathParams&) -> HttpResponse {
                 operational(default_printer(ctx.printers));
                 throw ApiError(409, "no_heated_chamber", "Printer does not have a heated chamber");
               });
  }
}

}  // namespace salient::server
