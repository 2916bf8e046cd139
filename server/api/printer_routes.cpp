// /api/v1/printers…: state, connection, prints and console commands.
#include <chrono>
#include <nlohmann/json.hpp>

#include "protocol/marlin/line_codec.hpp"
#include "server/api/api_json.hpp"
#include "server/api/printer_forwarding.hpp"
#include "server/api/printer_json.hpp"
#include "server/api/routes.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

HttpResponse status(int code, const Printer& p) {
  return json_response(code, printer_status_json(p.status()));
}

// In a farm, every printer says which node it is on; another node's is as that node last wrote
// it, "offline" when the node is dead.
json local_status(const Printer& p, const PrinterFarm* farm) {
  json out = printer_status_json(p.status());
  if (farm) out["node"] = farm->node();
  return out;
}

json remote_status(const FarmPrinter& p, const PrinterFarm& farm) {
  return farm_printer_json(p, farm.live(p));
}

// A handler for /api/v1/printers/{id}/…: run here when the printer is this node's, else carried
// to the node that owns it (`local_read`: answered here from the shared store instead, as reading
// the history needs no printer and works while its node is down).
Handler on_printer(PrinterService& printers, PrinterFarm* farm, Handler handler, bool local_read = false) {
  if (!farm) return handler;
  return
      [&printers, farm, handler = std::move(handler), local_read](const HttpRequest& r, const PathParams& p) {
        if (printers.find(p.at("id")) || local_read) return handler(r, p);
        if (auto remote = farm->other(p.at("id"))) return farm->forward(r, *remote);
        return handler(r, p);  // its NotFound
      };
}

long long entry_id(const PathParams& p) {
  const std::string& text = p.at("entry");
  if (text.empty() || text.size() > 18 || text.find_first_not_of("0123456789") != std::string::npos)
    throw ApiError(404, "not_found", "no queue entry '" + text.substr(0, 40) + "'");
  return std::stoll(text);
}

// {"job": ID} or {"file": NAME}: what to print (400 otherwise; `alternative` names what else
// the endpoint takes).
std::pair<std::string, std::string> print_request(const json& body, const std::string& alternative) {
  if (body.size() == 1)
    for (const char* kind : {"job", "file"})
      if (body.contains(kind) && body.at(kind).is_string()) return {kind, body.at(kind).get<std::string>()};
  throw ApiError(400, "bad_request",
                 "expected {\"job\": \"ID\"} or {\"file\": \"NAME\"}" +
                     (alternative.empty() ? std::string() : " or " + alternative));
}

HttpResponse queued(const QueueEntry& e) {
  return json_response(202,
                       {{"queued", true}, {"position", e.position}, {"entry", e.id}, {"slicing", e.slicing}});
}

HttpResponse started(const Printer& printer, long long print) {
  HttpResponse out = status(202, printer);
  out.headers.emplace_back("Location",
                           "/api/v1/printers/" + printer.id() + "/prints?print=" + std::to_string(print));
  return out;
}

// /api/v1/farm/{profile}/…: the farm-wide queue of a profile — any idle printer with it prints.
void add_farm_routes(Router& router, PrinterService& printers, const DaemonConfig& config) {
  router.add("POST", "/api/v1/farm/{profile}/print", Access::key,
             [&printers, &config](const HttpRequest& r, const PathParams& p) {
               const json body =
                   parse_json_body(r, config.max_json_bytes, static_cast<std::size_t>(config.max_json_depth));
               const auto [kind, ref] = print_request(body, "");
               const PrintSubmission sent = printers.submit_to_profile(p.at("profile"), kind, ref);
               if (sent.queued) return queued(*sent.queued);
               return started(printers.get(sent.printer), sent.print);
             });
  router.add("GET", "/api/v1/farm/{profile}/queue", Access::key,
             [&printers](const HttpRequest&, const PathParams& p) {
               return json_response(200, print_queue_json("profile/" + p.at("profile"),
                                                          printers.profile_queue(p.at("profile"))));
             });
  router.add("DELETE", "/api/v1/farm/{profile}/queue/{entry}", Access::key,
             [&printers](const HttpRequest&, const PathParams& p) {
               printers.remove_from_profile(p.at("profile"), entry_id(p));
               return json_response(200, print_queue_json("profile/" + p.at("profile"),
                                                          printers.profile_queue(p.at("profile"))));
             });
}

// …/queue: list, next (the bed is clear), remove and move entries.
void add_queue_routes(Router& router, PrinterService& printers, const DaemonConfig& config,
                      PrinterFarm* farm) {
  const auto listing = [&printers](const Printer& printer) {
    json out = print_queue_json(printer.id(), printers.queue(printer));
    out["auto_start"] = printer.config().auto_start;
    return out;
  };
  router.add("GET", "/api/v1/printers/{id}/queue", Access::key,
             on_printer(printers, farm, [&printers, listing](const HttpRequest&, const PathParams& p) {
               return json_response(200, listing(printers.get(p.at("id"))));
             }));
  router.add("POST", "/api/v1/printers/{id}/queue/next", Access::key,
             on_printer(printers, farm, [&printers](const HttpRequest&, const PathParams& p) {
               Printer& printer = printers.get(p.at("id"));
               const auto [print, entry] = printers.next(printer);
               json out = printer_status_json(printer.status());
               out["started"] = {{"entry", entry.id}, {"print", print}};
               return json_response(202, out);
             }));
  router.add("DELETE", "/api/v1/printers/{id}/queue/{entry}", Access::key,
             on_printer(printers, farm, [&printers, listing](const HttpRequest&, const PathParams& p) {
               Printer& printer = printers.get(p.at("id"));
               printers.remove_queued(printer, entry_id(p));
               return json_response(200, listing(printer));
             }));
  router.add(
      "POST", "/api/v1/printers/{id}/queue/{entry}/move", Access::key,
      on_printer(printers, farm, [&printers, &config, listing](const HttpRequest& r, const PathParams& p) {
        Printer& printer = printers.get(p.at("id"));
        const long long entry = entry_id(p);
        const json body =
            parse_json_body(r, config.max_json_bytes, static_cast<std::size_t>(config.max_json_depth));
        if (!body.is_object() || !body.contains("position") || !body.at("position").is_number_integer())
          throw ApiError(400, "bad_request", "expected {\"position\": N}, N from 1");
        printers.move_queued(printer, entry, body.at("position").get<long long>());
        return json_response(200, listing(printer));
      }));
}

}  // namespace

std::vector<std::string> parse_commands(const json& body) {
  json list;
  if (body.contains("commands"))
    list = body.at("commands");
  else if (body.contains("command"))
    list = json::array({body.at("command")});
  else
    throw ApiError(400, "bad_request", "expected {\"commands\": [\"G28\", …]}");
  if (!list.is_array() || list.empty() || list.size() > 1000)
    throw ApiError(400, "bad_request", "'commands' must be a list of 1 to 1000 G-code lines");
  std::vector<std::string> out;
  for (const json& c : list) {
    if (!c.is_string()) throw ApiError(400, "bad_request", "each command must be a string");
    const std::string line = c.get<std::string>();
    const std::string command = protocol::marlin::strip_comment(line);
    if (command.empty())
      throw ApiError(400, "bad_request", "each command must be a G-code command, not empty or a comment");
    // Well-formed but not the console's to send: 422, as a file holding it is refused.
    if (std::string why = protocol::marlin::numbering_command(command); !why.empty())
      throw ApiError(422, "host_command", "command '" + command.substr(0, 40) + "' cannot be sent: " + why);
    if (std::string why = protocol::marlin::unsendable(command); !why.empty())
      throw ApiError(400, "bad_request", "command '" + command.substr(0, 40) + "' cannot be sent: " + why);
    out.push_back(command);
  }
  return out;
}

void add_printer_routes(Router& router, PrinterService& printers, Store& store, const DaemonConfig& config,
                        PrinterFarm* farm) {
  router.add("GET", "/api/v1/printers", Access::key,
             [&printers, farm](const HttpRequest&, const PathParams&) {
               json list = json::array();
               for (const auto& p : printers.all()) list.push_back(local_status(*p, farm));
               if (farm)
                 for (const FarmPrinter& p : farm->others()) list.push_back(remote_status(p, *farm));
               return json_response(200, {{"printers", list}});
             });
  router.add("GET", "/api/v1/printers/{id}", Access::key,
             [&printers, farm](const HttpRequest&, const PathParams& p) {
               if (const Printer* local = printers.find(p.at("id")))
                 return json_response(200, local_status(*local, farm));
               if (farm)
                 if (auto remote = farm->other(p.at("id")))
                   return json_response(200, remote_status(*remote, *farm));
               return status(200, printers.get(p.at("id")));  // its NotFound
             });
  // A printer's prints and its history's sums are read from the store, here, whatever node
  // drives it (and while that node is down).
  const auto known = [&printers, farm](const std::string& id) {
    if (printers.find(id) || (farm && farm->other(id))) return id;
    return printers.get(id).id();  // its NotFound
  };
  router.add("GET", "/api/v1/printers/{id}/prints", Access::key,
             [&store, known](const HttpRequest&, const PathParams& p) {
               json list = json::array();
               for (const PrintRecord& r : PrintStore(store.db()).list(known(p.at("id")), 100))
                 list.push_back(print_record_json(r));
               return json_response(200, {{"prints", list}});
             });
  // The history in sums (Moonraker's history totals): per printer, and the farm's with each printer's.
  router.add("GET", "/api/v1/printers/{id}/history/totals", Access::key,
             [&store, known](const HttpRequest&, const PathParams& p) {
               return json_response(200, print_totals_json(PrintStore(store.db()).totals(known(p.at("id")))));
             });
  router.add("GET", "/api/v1/history/totals", Access::key,
             [&printers, &store, farm](const HttpRequest&, const PathParams&) {
               PrintStore prints(store.db());
               json out = print_totals_json(prints.totals(""));
               out["printers"] = json::object();
               for (const auto& printer : printers.all())
                 out["printers"][printer->id()] = print_totals_json(prints.totals(printer->id()));
               if (farm)
                 for (const FarmPrinter& p : farm->others())
                   out["printers"][p.id] = print_totals_json(prints.totals(p.id));
               return json_response(200, out);
             });
  // The last half hour of temperatures, for a chart: columns, then one row per sample (at most
  // one a second); null where the printer had not reported a value.
  router.add("GET", "/api/v1/printers/{id}/temperatures", Access::key,
             on_printer(printers, farm, [&printers](const HttpRequest&, const PathParams& p) {
               const TemperatureHistory& history = printers.temperatures(p.at("id"));
               const double now =
                   std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
               const auto value = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
               json rows = json::array();
               for (const TemperatureSample& s : history.samples(now))
                 rows.push_back({s.time, value(s.hotend.actual), value(s.hotend.target), value(s.bed.actual),
                                 value(s.bed.target)});
               return json_response(200,
                                    {{"printer", p.at("id")},
                                     {"window", history.window()},
                                     {"columns", {"time", "hotend", "hotend_target", "bed", "bed_target"}},
                                     {"samples", rows}});
             }));
  router.add("POST", "/api/v1/printers/{id}/connect", Access::key,
             on_printer(printers, farm, [&printers](const HttpRequest&, const PathParams& p) {
               Printer& printer = printers.get(p.at("id"));
               printer.connect();
               return status(202, printer);
             }));
  router.add("POST", "/api/v1/printers/{id}/disconnect", Access::key,
             on_printer(printers, farm, [&printers](const HttpRequest&, const PathParams& p) {
               Printer& printer = printers.get(p.at("id"));
               printer.disconnect();
               return status(202, printer);
             }));
  // {"job": ID} prints a finished job's G-code, {"file": NAME} an uploaded file, {"resume": PRINT}
  // the rest of an interrupted print (heaters, position and modes restored first).
  router.add("POST", "/api/v1/printers/{id}/print", Access::key,
             on_printer(printers, farm, [&printers, &config](const HttpRequest& r, const PathParams& p) {
               Printer& printer = printers.get(p.at("id"));
               const json body =
                   parse_json_body(r, config.max_json_bytes, static_cast<std::size_t>(config.max_json_depth));
               if (body.size() == 1 && body.contains("resume") && body.at("resume").is_number_integer()) {
                 const long long print = printers.resume(printer, body.at("resume").get<long long>());
                 return started(printer, print);
               }
               const auto [kind, ref] = print_request(body, "{\"resume\": PRINT_ID}");
               const PrintSubmission sent =
                   kind == "job" ? printers.submit_job(printer, ref) : printers.submit_file(printer, ref);
               if (sent.queued) return queued(*sent.queued);
               return started(printer, sent.print);
             }));
  add_queue_routes(router, printers, config, farm);
  add_farm_routes(router, printers, config);
  const std::pair<const char*, void (Printer::*)()> actions[] = {
      {"pause", &Printer::pause},
      {"resume", &Printer::resume},
      {"cancel", &Printer::cancel},
      {"emergency-stop", &Printer::emergency_stop}};
  for (const auto& [name, action] : actions) {
    router.add(
        "POST", std::string("/api/v1/printers/{id}/") + name, Access::key,
        on_printer(printers, farm, [&printers, action = action](const HttpRequest&, const PathParams& p) {
          Printer& printer = printers.get(p.at("id"));
          (printer.*action)();
          return status(202, printer);
        }));
  }
  router.add("POST", "/api/v1/printers/{id}/command", Access::key,
             on_printer(printers, farm, [&printers, &config](const HttpRequest& r, const PathParams& p) {
               Printer& printer = printers.get(p.at("id"));
               const json body =
                   parse_json_body(r, config.max_json_bytes, static_cast<std::size_t>(config.max_json_depth));
               bool force = false;
               if (body.is_object() && body.contains("force")) {
                 if (!body.at("force").is_boolean())
                   throw ApiError(400, "bad_request", "'force' must be true or false");
                 force = body.at("force").get<bool>();
               }
               printer.command(parse_commands(body), force);
               return status(202, printer);
             }));
}

}  // namespace salient::server
