#include "server/api/printer_forwarding.hpp"

#include <cctype>
#include <memory>
#include <nlohmann/json.hpp>

#include "server/common/json_text.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

// The request's target as this node's router sees it: without the base path a proxy put in front.
std::string local_target(const HttpRequest& r) {
  if (!r.base_path.empty() && r.target.rfind(r.base_path, 0) == 0) return r.target.substr(r.base_path.size());
  return r.target;
}

std::string headers_json(const std::vector<std::pair<std::string, std::string>>& headers,
                         const std::string& content_type) {
  json out = json::array();
  out.push_back({"Content-Type", content_type});
  for (const auto& [name, value] : headers) out.push_back({name, value});
  return json_text(out);
}

// The channel a node's executor listens on for new requests: the node id in a channel's
// alphabet (lower case, digits, '_'). Two ids that map alike only wake each other's executor.
std::string request_channel(const std::string& node) {
  std::string out = "salient_requests_";
  for (char c : node.substr(0, 40)) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += std::isalnum(u) ? static_cast<char>(std::tolower(u)) : '_';
  }
  return out;
}

HttpResponse from_answer(const PrinterAnswer& a) {
  HttpResponse out;
  out.status = a.status;
  out.body = a.body;
  try {
    for (const json& h : json::parse(a.headers)) {
      const std::string name = h.at(0).get<std::string>(), value = h.at(1).get<std::string>();
      if (name == "Content-Type")
        out.content_type = value;
      else
        out.headers.emplace_back(name, value);
    }
  } catch (const std::exception&) {  // written by a node of ours: kept as far as it goes
  }
  return out;
}

}  // namespace

double PrinterFarm::now() const {
  return FarmStore(store_.db()).clock();  // one clock for the farm: the hosts' may disagree
}

std::vector<FarmPrinter> PrinterFarm::others() {
  std::vector<FarmPrinter> out;
  for (FarmPrinter& p : FarmStore(store_.db()).printers())
    if (p.node != options_.node) out.push_back(std::move(p));
  return out;
}

std::optional<FarmPrinter> PrinterFarm::other(const std::string& id) {
  auto p = FarmStore(store_.db()).printer(id);
  if (!p || p->node == options_.node) return std::nullopt;
  return p;
}

bool PrinterFarm::live(const FarmPrinter& p) const {
  return p.heartbeat_age <= options_.lease_seconds;
}

bool PrinterFarm::profile_live(const std::string& profile) {
  return FarmStore(store_.db()).profile_live(profile, now() - options_.lease_seconds);
}

HttpResponse PrinterFarm::forward(const HttpRequest& request, const FarmPrinter& printer) {
  if (!live(printer))
    return error_response(503, "node_unavailable",
                          "printer " + printer.id + " is on node '" + printer.node +
                              "', which has not renewed its heartbeat for " +
                              std::to_string(static_cast<long long>(printer.heartbeat_age)) + " s");
  if (request.body.size() > options_.max_body_bytes)
    return error_response(413, "too_large",
                          "a request for a printer of another node may carry at most " +
                              std::to_string(options_.max_body_bytes) +
                              " bytes (upload G-code through /api/files/local)");
  if (waiting_.fetch_add(1) >= options_.max_waiting) {
    waiting_.fetch_sub(1);
    HttpResponse busy = error_response(
        503, "too_busy", "too many requests are waiting for other nodes; try again in a moment");
    busy.headers.emplace_back("Retry-After", "1");
    return busy;
  }
  try {
    HttpResponse out = carry(request, printer);
    waiting_.fetch_sub(1);
    return out;
  } catch (...) {
    waiting_.fetch_sub(1);
    throw;
  }
}

HttpResponse PrinterFarm::carry(const HttpRequest& request, const FarmPrinter& printer) {
  const Principal caller = request.caller.value_or(Principal{"admin", Role::admin, 0});
  FarmStore farm(store_.db());
  const long long id = farm.post({0, printer.node, request.method, local_target(request), request.body,
                                  caller.user, std::string(to_string(caller.role))},
                                 now());
  // Wakes the owning node's executor at once (it also polls, slowly, in case a wake is lost).
  if (store_.db().dialect() == Dialect::postgresql) {
    try {
      store_.db().notify(request_channel(printer.node), "");
    } catch (const StoreError&) {  // the request is in the table: the executor's poll finds it
    }
  }
  const auto wait_for_answer = [&](double seconds) -> std::optional<PrinterAnswer> {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    auto wait = std::chrono::milliseconds(2);
    while (std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(wait);
      wait = std::min(wait * 2, std::chrono::milliseconds(25));
      if (auto answer = farm.answer_of(id)) return answer;
    }
    return std::nullopt;
  };
  if (auto answer = wait_for_answer(options_.timeout_seconds)) return from_answer(*answer);
  const std::string who = "node '" + printer.node + "' (printer " + printer.id + ")";
  const std::string waited = std::to_string(static_cast<int>(options_.timeout_seconds)) + " s";
  // Cancelled while still pending: then it never runs, and "nothing was done" is true.
  if (farm.cancel(id))
    return error_response(
        504, "node_timeout",
        who + " did not take the request within " + waited + "; it was withdrawn: nothing was done");
  // Taken: the node is running it (a print that starts slowly), so its answer is the truth; it
  // gets as long again before the caller is told it may still happen.
  if (auto answer = farm.answer_of(id)) return from_answer(*answer);
  if (auto answer = wait_for_answer(options_.timeout_seconds)) return from_answer(*answer);
  return error_response(504, "node_timeout",
                        who + " took the request but did not answer within " +
                            std::to_string(static_cast<int>(2 * options_.timeout_seconds)) +
                            " s; it may still be carried out: look at the printer before trying again");
}

PrinterRequestExecutor::PrinterRequestExecutor(Store& store, const Router& router, std::string node)
    : store_(store), router_(router), node_(std::move(node)) {}

PrinterRequestExecutor::~PrinterRequestExecutor() {
  stop();
}

void PrinterRequestExecutor::start() {
  thread_ = std::thread([this] { loop(); });
}

void PrinterRequestExecutor::stop() {
  stopping_ = true;
  if (thread_.joinable() && store_.db().dialect() == Dialect::postgresql) {
    try {
      store_.db().notify(request_channel(node_), "");  // out of its wait now, not after kIdlePoll
    } catch (const std::exception&) {
    }
  }
  if (thread_.joinable()) thread_.join();
}

void PrinterRequestExecutor::loop() {
  auto last_purge = std::chrono::steady_clock::now();
  // On PostgreSQL a connection of its own listens for the API nodes' wake-ups, so that an idle
  // node costs the database one poll a second (kIdlePoll), not one every kPoll.
  std::unique_ptr<Database> listener;
  while (!stopping_) {
    try {
      if (!listener && store_.db().dialect() == Dialect::postgresql) {
        listener = std::make_unique<Database>(store_.database_url());
        listener->listen(request_channel(node_));
      }
    } catch (const std::exception&) {
      listener.reset();  // the database away: polled every kPoll until it is back
    }
    try {
      FarmStore farm(store_.db());
      const auto taken = farm.take(node_, 16);
      for (const PrinterRequest& r : taken) {
        const HttpResponse out = run(router_, r);
        farm.answer(r.id, {out.status, headers_json(out.headers, out.content_type), out.body}, farm.clock());
      }
      if (std::chrono::steady_clock::now() - last_purge > std::chrono::minutes(1)) {
        farm.purge(farm.clock() - 600);  // ours and the others': answers nobody waits for
        last_purge = std::chrono::steady_clock::now();
      }
      if (!taken.empty()) continue;
    } catch (const std::exception&) {  // the database away for a moment: the next poll may work
    }
    if (!listener) {
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    try {
      listener->wait_notification(kIdlePoll);  // a wake-up, or the slow poll: then take
    } catch (const std::exception&) {
      listener.reset();  // its connection broke: listen again on a new one
    }
  }
}

HttpResponse PrinterRequestExecutor::run(const Router& router, const PrinterRequest& r) {
  HttpRequest request;
  request.method = r.method;
  request.target = r.target;
  if (!split_target(r.target, request.path, request.query))
    return error_response(400, "bad_request", "malformed target");
  // Only what an API node forwards: a printer's own routes.
  if (request.path.rfind("/api/v1/printers/", 0) != 0)
    return error_response(400, "bad_request", "only /api/v1/printers/{id}/… is run for another node");
  request.body = r.body;
  if (!r.body.empty()) request.headers["content-type"] = "application/json";
  request.caller = Principal{r.user, role_from(r.role).value_or(Role::viewer), 0};
  request.remote = "node";
  PathParams params;
  for (const Route& route : router.routes()) {
    if (!match_pattern(route.pattern, request.path, params)) continue;
    if (route.method != request.method && !(request.method == "HEAD" && route.method == "GET")) continue;
    const std::optional<Role> needed = needed_role(route.access, request.method);
    if (needed && request.caller->role < *needed)
      return error_response(403, "forbidden", "the caller's role may not do this");
    try {
      return route.handler(request, params);
    } catch (const ApiError& e) {
      HttpResponse out = error_response(e.status(), e.code(), e.what());
      out.headers.insert(out.headers.end(), e.headers().begin(), e.headers().end());
      return out;
    } catch (const DomainError& e) {
      return domain_error_response(e);
    } catch (const std::exception&) {
      return error_response(500, "internal", "internal error on the printer's node");
    }
  }
  return error_response(404, "not_found", "no such endpoint: " + request.path.substr(0, 256));
}

}  // namespace salient::server
