// event_relay_bench: the latency of an event across nodes. Two relays on one PostgreSQL (node A
// publishes, node B's hub has the subscriber), in one process so that one clock times both ends:
// from EventHub::publish on A to the subscriber's queue on B (NOTIFY, commit, the listener, the
// hub). Printer events go through A's sender thread; job events are sent on the publishing
// thread's connection. Each kind is run at a fixed rate and as fast as one thread publishes.
//   event_relay_bench POSTGRESQL_URL [EVENTS] [RATE_PER_SECOND]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "server/events/event_relay.hpp"
#include "server/store/store.hpp"

using namespace salient::server;
using Clock = std::chrono::steady_clock;

namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

struct Node {
  std::filesystem::path dir;
  Store store;
  EventHub hub;
  EventRelay relay;
  Node(const std::string& name, const DatabaseUrl& url)
      : dir(std::filesystem::temp_directory_path() / ("salient-relay-bench-" + name)),
        store(dir, url),
        hub(EventHubOptions{1u << 20, 1u << 20, 1u << 30}),
        relay(
            url, hub, [this]() -> Database& { return store.db(); }, options(name)) {}
  static EventRelayOptions options(const std::string& name) {
    EventRelayOptions o;
    o.node = name;
    o.queue_limit = 1u << 20;  // every event is a sample: none dropped
    return o;
  }
};

// Runs `events` events (a fixed `rate` per second, or 0: as fast as possible) from A to B and
// prints the latency percentiles.
void run(Node& a, Node& b, bool job, int events, int rate) {
  const std::string subject = job ? "job/bench" : "printer/bench";
  std::mutex mutex;
  std::condition_variable cv;
  bool woken = false;
  auto sub = b.hub.subscribe([&] {
    std::lock_guard lock(mutex);
    woken = true;
    cv.notify_all();
  });
  sub->subscribe(subject);
  while (sub->next()) {
  }
  std::vector<double> latency_ms;
  latency_ms.reserve(static_cast<std::size_t>(events));
  std::thread reader([&] {
    while (static_cast<int>(latency_ms.size()) < events) {
      std::unique_lock lock(mutex);
      cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return woken; });
      woken = false;
      lock.unlock();
      while (auto m = sub->next()) {
        const auto j = nlohmann::json::parse(*m);
        if (j["type"] != "bench") continue;
        latency_ms.push_back(static_cast<double>(now_ns() - j["data"]["t"].get<std::int64_t>()) / 1e6);
      }
    }
  });
  const auto start = Clock::now();
  for (int i = 0; i < events; ++i) {
    if (rate > 0) std::this_thread::sleep_until(start + std::chrono::microseconds(1000000LL * i / rate));
    const std::string data = nlohmann::json{{"i", i}, {"t", now_ns()}}.dump();
    a.hub.publish({job ? "jobs" : "printers", subject}, "bench", data);
  }
  const double publish_s = std::chrono::duration<double>(Clock::now() - start).count();
  reader.join();
  const double total_s = std::chrono::duration<double>(Clock::now() - start).count();
  sub->closed();
  std::sort(latency_ms.begin(), latency_ms.end());
  const auto at = [&](double q) { return latency_ms[static_cast<std::size_t>(q * (latency_ms.size() - 1))]; };
  std::printf(
      "%-7s %-10s events=%d publish=%.0f/s delivered=%.0f/s  latency ms: p50=%.2f p99=%.2f max=%.2f\n",
      job ? "job" : "printer", rate > 0 ? (std::to_string(rate) + "/s").c_str() : "max-rate", events,
      events / publish_s, events / total_s, at(0.5), at(0.99), latency_ms.back());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: event_relay_bench POSTGRESQL_URL [EVENTS] [RATE_PER_SECOND]\n");
    return 2;
  }
  const DatabaseUrl url = DatabaseUrl::parse(argv[1]);
  const int events = argc > 2 ? std::stoi(argv[2]) : 5000;
  const int rate = argc > 3 ? std::stoi(argv[3]) : 1000;
  try {
    Node a("a", url), b("b", url);
    a.relay.start();
    b.relay.start();
    {
      Database db(url);
      auto show = db.prepare("SHOW fsync");
      show.step();
      std::printf("event_relay_bench: %d events a run; PostgreSQL fsync=%s\n", events, show.text(0).c_str());
    }
    for (bool job : {false, true}) {
      run(a, b, job, events, rate);
      run(a, b, job, events, 0);
    }
    const EventRelayStats s = a.relay.stats();
    std::printf("node A sent %ju events (%ju coalesced, %ju dropped)\n", static_cast<std::uintmax_t>(s.sent),
                static_cast<std::uintmax_t>(s.coalesced), static_cast<std::uintmax_t>(s.dropped));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "event_relay_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
