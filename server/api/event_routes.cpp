// The WebSocket /api/v1/events: who may connect, what a new subscriber sees first, and how job
// changes become events.
#include <atomic>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unordered_map>

#include "server/api/api_json.hpp"
#include "server/api/printer_forwarding.hpp"
#include "server/api/printer_json.hpp"
#include "server/api/routes.hpp"
#include "server/common/json_text.hpp"
#include "server/store/job_store.hpp"

namespace salient::server {

namespace {

// A browser's WebSocket cannot send headers, and a key in the URL would land in proxies' logs: the
// page offers the key as a subprotocol, "salient-key.KEY", beside "salient.v1". The answer names
// the plain one, so the key is not even echoed back.
struct OfferedProtocols {
  std::string key;     // from "salient-key.KEY"; empty: none offered
  std::string chosen;  // what the handshake answers with; empty: nothing was offered
};

OfferedProtocols offered_protocols(const HttpRequest& r) {
  static constexpr std::string_view kKeyPrefix = "salient-key.";
  OfferedProtocols out;
  std::string first_plain, key_protocol;
  std::stringstream list(r.header("sec-websocket-protocol"));
  for (std::string p; std::getline(list, p, ',');) {
    p.erase(0, p.find_first_not_of(" \t"));
    p.erase(p.find_last_not_of(" \t") + 1);
    if (p.rfind(kKeyPrefix, 0) == 0) {
      if (out.key.empty()) out.key = p.substr(kKeyPrefix.size()), key_protocol = p;
    } else if (!p.empty() && first_plain.empty()) {
      first_plain = p;
    }
  }
  out.chosen = !first_plain.empty() ? first_plain : key_protocol;
  return out;
}

// A subscription that ends with its key: revoked on any node, the connection is closed (1008,
// saying why) at once, instead of streaming on to whoever holds the old key.
class KeyedChannel : public WebSocketChannel {
 public:
  explicit KeyedChannel(std::shared_ptr<WebSocketChannel> inner) : inner_(std::move(inner)) {}
  void open(std::function<void()> wake) override {
    {
      std::lock_guard lock(mutex_);
      wake_ = wake;
    }
    inner_->open(std::move(wake));
  }
  void receive(const std::string& text) override { inner_->receive(text); }
  std::optional<std::string> next() override { return revoked_ ? std::nullopt : inner_->next(); }
  std::string close_reason() override {
    return revoked_ ? "the API key was revoked: connect again with a valid key" : inner_->close_reason();
  }
  void closed() override { inner_->closed(); }
  void hold(std::shared_ptr<KeyWatch> watch) { watch_ = std::move(watch); }
  void revoke() {
    revoked_ = true;
    std::function<void()> wake;
    {
      std::lock_guard lock(mutex_);
      wake = wake_;
    }
    if (wake) wake();  // not open yet: pump() sees the flag when it is
  }

 private:
  std::shared_ptr<WebSocketChannel> inner_;
  std::atomic<bool> revoked_{false};
  std::mutex mutex_;
  std::function<void()> wake_;
  std::shared_ptr<KeyWatch> watch_;
};

}  // namespace

WebSocketAcceptor events_endpoint(EventHub& hub, ApiKeys& keys) {
  return [&hub, &keys](const HttpRequest& r) -> WebSocketAccept {
    if (r.path != "/api/v1/events")
      return {nullptr, error_response(404, "not_found", "no WebSocket at " + r.path)};
    const OfferedProtocols offered = offered_protocols(r);
    std::optional<Principal> who = keys.authenticate(r);
    if (!who) who = keys.principal(offered.key);
    if (!who)
      return {nullptr, error_response(401, "unauthorized",
                                      "send the API key (X-Api-Key, Authorization: Bearer, the subprotocol "
                                      "salient-key.KEY, or ?apikey=)")};
    auto subscription = hub.subscribe();
    // ?topics=jobs,printer/sim subscribes at once (a client may also send {"subscribe": […]}).
    if (const auto it = r.query.find("topics"); it != r.query.end()) {
      std::stringstream list(it->second);
      for (std::string topic; std::getline(list, topic, ',');) {
        if (!topic.empty() && !subscription->subscribe(topic)) {
          subscription->closed();
          return {nullptr, error_response(400, "bad_request",
                                          "unknown topic '" + topic +
                                              "': use jobs, job/ID, printers, printer/ID or terminal/ID")};
        }
      }
    }
    auto channel = std::make_shared<KeyedChannel>(subscription);
    // The watch lives as long as the connection: the channel holds it.
    auto watch = std::make_shared<KeyWatch>();
    watch->key_id = who->key_id;
    watch->revoked = [weak = std::weak_ptr<KeyedChannel>(channel)] {
      if (const auto c = weak.lock()) c->revoke();
    };
    channel->hold(watch);
    keys.watch(watch);
    return {channel, {}, offered.chosen};
  };
}

void add_event_route(Router& router) {
  // The same path without an upgrade: say how to connect (and, through the router, 401 first).
  router.add("GET", "/api/v1/events", Access::key, [](const HttpRequest&, const PathParams&) {
    HttpResponse r =
        error_response(426, "upgrade_required",
                       "/api/v1/events is a WebSocket: connect with Upgrade: websocket, then send "
                       "{\"subscribe\": [\"jobs\"]}");
    r.headers.emplace_back("Upgrade", "websocket");
    return r;
  });
}

SnapshotFn event_snapshots(Store& store, PrinterService& printers, PrinterFarm* farm) {
  return [&store, &printers, farm](const std::string& topic) {
    std::vector<std::pair<std::string, std::string>> out;
    if (topic == "jobs") {  // the jobs that are not finished yet, oldest first
      JobStore jobs(store.db());
      for (JobState state : {JobState::running, JobState::queued}) {
        std::vector<Job> list = jobs.list(state, 256, 0);
        for (auto j = list.rbegin(); j != list.rend(); ++j) out.emplace_back("job", json_text(job_json(*j)));
      }
    } else if (topic.rfind("job/", 0) == 0) {
      if (auto j = JobStore(store.db()).get(topic.substr(4)))
        out.emplace_back("job", json_text(job_json(*j)));
    } else if (topic == "printers") {
      for (const auto& p : printers.all())
        out.emplace_back("printer", json_text(printer_status_json(p->status())));
      if (farm)
        for (const FarmPrinter& p : farm->others())
          out.emplace_back("printer", json_text(farm_printer_json(p, farm->live(p))));
    } else if (topic.rfind("printer/", 0) == 0) {
      for (const auto& p : printers.all())
        if (p->id() == topic.substr(8))
          out.emplace_back("printer", json_text(printer_status_json(p->status())));
      if (out.empty() && farm)
        if (const auto p = farm->other(topic.substr(8)))
          out.emplace_back("printer", json_text(farm_printer_json(*p, farm->live(*p))));
    }
    return out;
  };
}

std::function<void(const Job&)> job_event_publisher(EventHub& hub) {
  // A change of state or phase is a state change (always delivered); anything else is progress.
  struct Seen {
    std::mutex mutex;
    std::unordered_map<std::string, std::string> last;
  };
  auto seen = std::make_shared<Seen>();
  return [&hub, seen](const Job& j) {
    const std::string key = std::string(to_string(j.state)) + "/" + std::string(to_string(j.phase));
    bool progress;
    {
      std::lock_guard lock(seen->mutex);
      auto& last = seen->last[j.id];
      progress = last == key;
      last = key;
      if (finished(j.state)) seen->last.erase(j.id);
    }
    hub.publish({"jobs", "job/" + j.id}, "job", json_text(job_json(j)),
                progress ? Delivery::coalesce : Delivery::always);
  };
}

PrinterEvents printer_event_publisher(EventHub& hub) {
  PrinterEvents e;
  e.changed = [&hub](const Printer& printer, bool progress) {
    hub.publish({"printers", "printer/" + printer.id()}, "printer",
                json_text(printer_status_json(printer.status())),
                progress ? Delivery::coalesce : Delivery::always);
  };
  e.queue_changed = [&hub](const std::string& key, const std::vector<QueueEntry>& entries) {
    // A printer's queue also on its own topic; a farm queue ("farm/PROFILE") on "printers" only.
    std::vector<std::string> topics{"printers"};
    if (key.find('/') == std::string::npos) topics.push_back("printer/" + key);
    hub.publish(topics, "queue", json_text(print_queue_json(key, entries)));
  };
  e.terminal_wanted = [&hub](const Printer& printer) {
    return hub.has_subscribers("terminal/" + printer.id());
  };
  e.terminal = [&hub](const Printer& printer, bool sent, std::string_view line) {
    hub.publish(
        {"terminal/" + printer.id()}, "terminal",
        json_text(nlohmann::json{{"direction", sent ? "sent" : "received"}, {"line", std::string(line)}}),
        Delivery::best_effort);
  };
  return e;
}

}  // namespace salient::server
