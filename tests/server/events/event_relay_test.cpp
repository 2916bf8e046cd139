// EventRelay on a real PostgreSQL: two nodes (two relays, two hubs, one database). What one node
// publishes reaches the other's subscribers complete and in order per topic; state changes are
// never lost; large events arrive whole; a job event in a transaction goes with its commit; a
// killed listening connection comes back with a resync.
#include "server/events/event_relay.hpp"

#include <doctest/doctest.h>

#include <atomic>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// One node: its own data directory and hub, the shared database, a relay.
struct Node {
  salient::test::ScratchDir dir;
  Store store;
  EventHub hub;
  EventRelay relay;
  Node(const std::string& name, const DatabaseUrl& url, EventRelayOptions options = {})
      : dir("relay-" + name),
        store(dir.path, url),
        hub(EventHubOptions{100000, 100000, 256u << 20}),
        relay(
            url, hub, [this]() -> Database& { return store.db(); }, with_node(options, name)) {}
  static EventRelayOptions with_node(EventRelayOptions o, const std::string& name) {
    o.node = name;
    return o;
  }
};

// Collects what a subscription receives, on a thread of its own as a WebSocket session would.
struct Collector {
  std::shared_ptr<Subscription> sub;
  std::mutex mutex;
  std::vector<json> got;
  std::atomic<bool> done{false};
  std::thread reader;
  Collector(EventHub& hub, const std::vector<std::string>& topics) : sub(hub.subscribe()) {
    for (const auto& t : topics) REQUIRE(sub->subscribe(t));
    while (sub->next()) {  // the "subscribed" replies
    }
    reader = std::thread([this] {
      while (!done) {
        bool any = false;
        while (auto m = sub->next()) {
          std::lock_guard lock(mutex);
          got.push_back(json::parse(*m));
          any = true;
        }
        if (!any) std::this_thread::sleep_for(1ms);
      }
    });
  }
  ~Collector() {
    done = true;
    reader.join();
  }
  std::vector<json> snapshot() {
    std::lock_guard lock(mutex);
    return got;
  }
  // Waits until `pred(received)` holds, or 30 s.
  template <class Pred>
  bool wait(Pred pred) {
    for (auto end = std::chrono::steady_clock::now() + 30s; std::chrono::steady_clock::now() < end;) {
      if (pred(snapshot())) return true;
      std::this_thread::sleep_for(10ms);
    }
    return pred(snapshot());
  }
};

std::size_t count_type(const std::vector<json>& v, const std::string& type) {
  return static_cast<std::size_t>(
      std::count_if(v.begin(), v.end(), [&](const json& j) { return j["type"] == type; }));
}

}  // namespace

TEST_CASE("two nodes: 1000 events from 4 threads on A reach B complete and in order per topic") {
  const salient::test::ScratchDir scratch("relay-order");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node a("a", url), b("b", url);
  std::mutex seen_mutex;
  std::map<std::string, int> remote_on_b, local_on_a;
  b.relay.on_event([&](const RelayedEvent& e) {
    std::lock_guard lock(seen_mutex);
    ++remote_on_b[e.local ? "local" : "remote"];
  });
  a.relay.on_event([&](const RelayedEvent& e) {
    std::lock_guard lock(seen_mutex);
    ++local_on_a[e.local ? "local" : "remote"];
  });
  a.relay.start();
  b.relay.start();
  constexpr int threads = 4, per_thread = 250;
  std::vector<std::string> topics = {"jobs", "printers"};
  for (int t = 0; t < threads; ++t) {
    topics.push_back("job/j" + std::to_string(t));
    topics.push_back("printer/p" + std::to_string(t));
    topics.push_back("terminal/p" + std::to_string(t));
  }
  Collector on_b(b.hub, topics);
  // Each thread: its job's events (sent on its own connection) and its printer's (through the
  // sender): states, progress between them, terminal lines.
  std::vector<std::thread> publishers;
  for (int t = 0; t < threads; ++t)
    publishers.emplace_back([&, t] {
      const std::string id = std::to_string(t);
      for (int i = 0; i < per_thread; ++i) {
        const std::string data = json{{"i", i}, {"t", t}}.dump();
        switch (i % 5) {
          case 0:
            a.hub.publish({"jobs", "job/j" + id}, "job", data);
            break;
          case 1:
            a.hub.publish({"jobs", "job/j" + id}, "job", data, Delivery::coalesce);
            break;
          case 2:
            a.hub.publish({"printers", "printer/p" + id}, "printer", data);
            break;
          case 3:
            a.hub.publish({"printers", "printer/p" + id}, "printer", data, Delivery::coalesce);
            break;
          default:
            a.hub.publish({"terminal/p" + id}, "terminal", data, Delivery::best_effort);
        }
      }
    });
  for (auto& p : publishers) p.join();
  // Every state change arrives: 2 of each 5 events, 400 in all.
  const auto states = [](const std::vector<json>& v) {
    return static_cast<int>(std::count_if(v.begin(), v.end(), [](const json& j) {
      return j["data"]["i"].get<int>() % 5 == 0 || j["data"]["i"].get<int>() % 5 == 2;
    }));
  };
  REQUIRE(on_b.wait([&](const auto& v) { return states(v) >= threads * per_thread * 2 / 5; }));
  std::this_thread::sleep_for(300ms);  // anything late (a duplicate) would show now
  const auto got = on_b.snapshot();
  CHECK(states(got) == threads * per_thread * 2 / 5);
  // In order per topic (the event's subject): each subject's numbers strictly increase.
  std::map<std::string, int> last;
  for (const json& j : got) {
    const std::string subject = j["topic"];
    const int i = j["data"]["i"];
    if (last.count(subject)) CHECK_MESSAGE(i > last[subject], subject, ": ", i, " after ", last[subject]);
    last[subject] = i;
  }
  // Nothing dropped here: the queue never reached its bound.
  CHECK(got.size() == static_cast<std::size_t>(threads * per_thread - a.relay.stats().coalesced));
  for (int i = 0; i < 1000; ++i) {  // the observers run on a thread of their own: a little later
    std::lock_guard lock(seen_mutex);
    if (remote_on_b["remote"] >= static_cast<int>(got.size()) &&
        local_on_a["local"] >= static_cast<int>(got.size()))
      break;
    std::this_thread::sleep_for(10ms);
  }
  std::lock_guard lock(seen_mutex);
  CHECK(remote_on_b["local"] == 0);
  CHECK(remote_on_b["remote"] == static_cast<int>(got.size()));
  CHECK(local_on_a["remote"] == 0);
  CHECK(local_on_a["local"] == static_cast<int>(got.size()));
}

TEST_CASE("two nodes: a 20 kB event arrives whole, through the sender and on the job's connection") {
  const salient::test::ScratchDir scratch("relay-large");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node a("a", url), b("b", url);
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"printer/big", "job/big"});
  std::string line(20000, 'x');
  for (std::size_t i = 0; i < line.size(); ++i) line[i] = static_cast<char>('a' + i % 26);
  const std::string data = json{{"line", line}}.dump();
  a.hub.publish({"printers", "printer/big"}, "printer", data);
  a.hub.publish({"jobs", "job/big"}, "job", data);
  REQUIRE(on_b.wait([](const auto& v) { return v.size() >= 2; }));
  for (const json& j : on_b.snapshot()) CHECK(j["data"].dump() == data);
  CHECK(a.relay.stats().stored == 2);
}

TEST_CASE("a job event published inside a transaction is delivered at its commit, never on rollback") {
  const salient::test::ScratchDir scratch("relay-tx");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node a("a", url), b("b", url);
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"jobs"});
  {
    Database::Transaction t(a.store.db());
    a.hub.publish({"jobs", "job/x"}, "job", R"({"state":"rolled back"})");
  }
  {
    Database::Transaction t(a.store.db());
    a.hub.publish({"jobs", "job/x"}, "job", R"({"state":"queued"})");
    std::this_thread::sleep_for(300ms);
    CHECK(on_b.snapshot().empty());  // not before the commit
    t.commit();
  }
  REQUIRE(on_b.wait([](const auto& v) { return !v.empty(); }));
  std::this_thread::sleep_for(200ms);
  const auto got = on_b.snapshot();
  REQUIRE(got.size() == 1);
  CHECK(got[0]["data"]["state"] == "queued");
}

TEST_CASE("connections killed by pg_terminate_backend: listeners reconnect and resync, senders send again") {
  const salient::test::ScratchDir scratch("relay-kill");
  const DatabaseUrl url = salient::test::test_database(scratch);
  EventRelayOptions quiet;
  quiet.ping_interval = std::chrono::hours(1);  // the listener's last query stays its LISTEN
  Node a("a", url), b("b", url, quiet);
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"printers", "jobs"});
  a.hub.publish({"printers", "printer/p"}, "printer", R"({"n":1})");
  REQUIRE(on_b.wait([](const auto& v) { return v.size() == 1; }));
  Database admin(url);
  a.hub.publish({"jobs", "job/j"}, "job", R"({"n":2})");  // the test thread's connection, for killing
  REQUIRE(on_b.wait([](const auto& v) { return v.size() == 2; }));
  // Every connection but this one: both listeners, A's sender, the test thread's.
  auto kill = admin.prepare(
      "SELECT pg_terminate_backend(pid), query FROM pg_stat_activity WHERE datname = current_database() AND "
      "pid <> pg_backend_pid()");
  int listeners = 0;
  while (kill.step()) listeners += kill.text(1).rfind("LISTEN", 0) == 0;
  REQUIRE(listeners == 2);
  REQUIRE(on_b.wait([](const auto& v) { return count_type(v, "resync") == 1; }));
  CHECK(b.relay.stats().reconnects >= 1);
  // The sender finds its connection dead and sends again on a new one; the job event's connection
  // was dead too, and is opened again before its statement (postgres_backend.cpp, revive). The two
  // go by two connections, so only each topic's own order holds between them.
  a.hub.publish({"printers", "printer/p"}, "printer", R"({"n":3})");
  a.hub.publish({"jobs", "job/j"}, "job", R"({"n":4})");
  REQUIRE(on_b.wait([](const auto& v) { return v.size() == 5; }));
  const auto got = on_b.snapshot();
  CHECK(got[0]["data"]["n"] == 1);
  CHECK(got[1]["data"]["n"] == 2);
  CHECK(got[2]["type"] == "resync");
  CHECK(got[3]["data"]["n"].get<int>() + got[4]["data"]["n"].get<int>() == 7);  // 3 and 4, each once
  CHECK(got[3]["data"]["n"] != got[4]["data"]["n"]);
}

TEST_CASE("a notification that is not an event (anyone may NOTIFY the channel) is skipped") {
  const salient::test::ScratchDir scratch("relay-junk");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node b("b", url);
  b.relay.start();
  Collector on_b(b.hub, {"printers"});
  Database other(url);
  for (const char* junk : {"", "hello", "{}\n{}", "@12345", "@x",
                           "{\"n\":\"z\",\"s\":1,\"v\":9,\"y\":\"t\",\"t\":[\"printers\"]}\n1",
                           "{\"n\":\"z\",\"s\":1,\"v\":0,\"y\":\"t\",\"t\":[\"../etc\"]}\n1"})
    other.notify("salient_events", junk);
  other.notify("salient_events",
               "{\"n\":\"z\",\"s\":1,\"v\":0,\"y\":\"printer\",\"t\":[\"printers\"]}\n{\"ok\":true}");
  REQUIRE(on_b.wait([](const auto& v) { return !v.empty(); }));
  const auto got = on_b.snapshot();
  REQUIRE(got.size() == 1);
  CHECK(got[0]["data"]["ok"] == true);
}

TEST_CASE("finished_job: the id of a job a job event says is done, failed or cancelled, and nothing else") {
  const auto event = [](std::vector<std::string> topics, std::string type, std::string data) {
    RelayedEvent e;
    e.topics = std::move(topics);
    e.type = std::move(type);
    e.data_json = std::move(data);
    return e;
  };
  for (const char* state : {"done", "failed", "cancelled"})
    CHECK(finished_job(event({"jobs", "job/j1"}, "job", json{{"id", "j1"}, {"state", state}}.dump())) ==
          "j1");
  for (const char* state : {"queued", "running", "exploded"})
    CHECK(!finished_job(event({"jobs", "job/j1"}, "job", json{{"id", "j1"}, {"state", state}}.dump())));
  CHECK(!finished_job(event({"printers", "printer/p"}, "job", R"({"state":"done"})")));
  CHECK(!finished_job(event({"jobs", "job/j1"}, "printer", R"({"state":"done"})")));
  CHECK(!finished_job(event({"jobs", "job/j1"}, "job", R"({"state":1})")));
  CHECK(!finished_job(event({"jobs", "job/j1"}, "job", "not json")));
  CHECK(!finished_job(event({}, "job", R"({"state":"done"})")));
}

TEST_CASE("a job finished on node A reaches node B's observers as remote, A's as local, off the listener") {
  const salient::test::ScratchDir scratch("relay-observe");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node a("a", url), b("b", url);
  std::mutex mutex;
  std::vector<std::string> finished_on_b, local_on_a;
  std::atomic<bool> slow_done{false};
  b.relay.on_event([&](const RelayedEvent& e) {
    if (e.local) return;
    if (const auto job = finished_job(e)) {
      // A slow observer (starting a print) delays no subscriber: long enough that a loaded
      // machine (ASan, 2 cores) still delivers the three events while it sleeps.
      std::this_thread::sleep_for(3s);
      std::lock_guard lock(mutex);
      finished_on_b.push_back(*job);
      slow_done = true;
    }
  });
  a.relay.on_event([&](const RelayedEvent& e) {
    std::lock_guard lock(mutex);
    if (const auto job = finished_job(e); job && e.local) local_on_a.push_back(*job);
  });
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"jobs"});
  a.hub.publish({"jobs", "job/j7"}, "job", R"({"id":"j7","state":"running"})");
  a.hub.publish({"jobs", "job/j7"}, "job", R"({"id":"j7","state":"done"})");
  a.hub.publish({"jobs", "job/j8"}, "job", R"({"id":"j8","state":"queued"})");
  REQUIRE(on_b.wait([](const auto& v) { return v.size() == 3; }));
  CHECK(!slow_done);  // the subscriber had all three while the observer still slept
  for (int i = 0; i < 1000 && !slow_done; ++i) std::this_thread::sleep_for(10ms);
  std::lock_guard lock(mutex);
  CHECK(finished_on_b == std::vector<std::string>{"j7"});
  CHECK(local_on_a == std::vector<std::string>{"j7"});
}

TEST_CASE(
    "a backlog at the sender: progress coalesces, terminal lines drop, state changes all arrive in order") {
  const salient::test::ScratchDir scratch("relay-backlog");
  const DatabaseUrl url = salient::test::test_database(scratch);
  EventRelayOptions small;
  small.queue_limit = 16;
  Node a("a", url, small), b("b", url);
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"printers", "terminal/p"});
  constexpr int events = 3000;
  for (int i = 0; i < events; ++i) {  // far faster than one connection sends them
    const std::string data = json{{"i", i}}.dump();
    if (i % 10 == 0)
      a.hub.publish({"printers", "printer/p"}, "printer", data);
    else if (i % 2 == 0)
      a.hub.publish({"printers", "printer/p"}, "printer", data, Delivery::coalesce);
    else
      a.hub.publish({"terminal/p"}, "terminal", data, Delivery::best_effort);
  }
  const auto states = [](const std::vector<json>& v) {
    return std::count_if(v.begin(), v.end(),
                         [](const json& j) { return j["data"]["i"].get<int>() % 10 == 0; });
  };
  REQUIRE(on_b.wait([&](const auto& v) { return states(v) == events / 10; }));
  // Every event the sender sent reaches B's node (the last ones after the last state change:
  // waited for, not slept for, as a loaded machine may take its time). B's client may see fewer:
  // its own queue coalesces progress it has not read yet, by the same rules.
  const auto all_received = [&] {
    const EventRelayStats s = a.relay.stats();
    return s.sent + s.coalesced + s.dropped == static_cast<std::uint64_t>(events) &&
           b.relay.stats().received == s.sent;
  };
  for (int i = 0; i < 3000 && !all_received(); ++i) std::this_thread::sleep_for(10ms);
  CHECK(all_received());
  const auto got = on_b.snapshot();
  CHECK(states(got) == events / 10);
  std::map<std::string, int> last;
  for (const json& j : got) {
    const std::string subject = j["topic"];
    const int i = j["data"]["i"];
    if (last.count(subject)) CHECK(i > last[subject]);
    last[subject] = i;
  }
  const EventRelayStats s = a.relay.stats();
  MESSAGE("sent ", s.sent, ", coalesced ", s.coalesced, ", dropped ", s.dropped, ", received on B ",
          got.size());
  CHECK(s.coalesced + s.dropped > 0);
  CHECK(b.relay.stats().received == events - s.coalesced - s.dropped);
  CHECK(got.size() <= b.relay.stats().received);
}

TEST_CASE("terminal lines across nodes: a subscriber on B makes A's has_subscribers true, until it leaves") {
  const salient::test::ScratchDir scratch("relay-interest");
  const DatabaseUrl url = salient::test::test_database(scratch);
  EventRelayOptions fast;
  fast.interest_interval = 500ms;  // interest lapses 3 intervals after the last announcement
  Node a("a", url, fast), b("b", url, fast);
  a.relay.start();
  b.relay.start();
  CHECK(!a.hub.has_subscribers("terminal/p"));
  auto on_b = std::make_unique<Collector>(b.hub, std::vector<std::string>{"terminal/p"});
  const auto wanted_on_a = [&] {
    for (int i = 0; i < 500; ++i) {
      if (a.hub.has_subscribers("terminal/p")) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  };
  REQUIRE(wanted_on_a());
  CHECK(!a.hub.has_subscribers("terminal/q"));
  a.hub.publish({"terminal/p"}, "terminal", R"({"line":"ok T:21"})", Delivery::best_effort);
  REQUIRE(on_b->wait([](const auto& v) { return v.size() == 1; }));
  CHECK(on_b->snapshot()[0]["data"]["line"] == "ok T:21");
  // Still wanted after several intervals (announced again), then not once B's client is gone.
  std::this_thread::sleep_for(2500ms);
  CHECK(a.hub.has_subscribers("terminal/p"));
  on_b->sub->closed();
  on_b.reset();
  bool gone = false;
  for (int i = 0; i < 1000 && !gone; ++i) {
    gone = !a.hub.has_subscribers("terminal/p");
    if (!gone) std::this_thread::sleep_for(10ms);
  }
  CHECK(gone);
}

TEST_CASE("an event the database refuses (invalid UTF-8) is given up and blocks none behind it") {
  const salient::test::ScratchDir scratch("relay-poison");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node a("a", url), b("b", url);
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"printers"});
  a.hub.publish({"printers", "printer/p"}, "printer", "\"\xff\xfe\"");
  a.hub.publish({"printers", "printer/p"}, "printer", R"({"ok":true})");
  REQUIRE(on_b.wait([](const auto& v) { return !v.empty(); }));
  const auto got = on_b.snapshot();
  REQUIRE(got.size() == 1);
  CHECK(got[0]["data"]["ok"] == true);
  CHECK(a.relay.stats().dropped == 1);
}

TEST_CASE("events sent in one batch keep their bytes: quotes, backslashes, braces, commas, non-ASCII") {
  const salient::test::ScratchDir scratch("relay-bytes");
  const DatabaseUrl url = salient::test::test_database(scratch);
  Node a("a", url), b("b", url);
  a.relay.start();
  b.relay.start();
  Collector on_b(b.hub, {"printer/p"});
  std::vector<std::string> sent;
  for (int i = 0; i < 200; ++i) {  // faster than one round trip each: batches of several
    std::string line = "M117 \"a\\\\b\" {x,y} NULL , \\\" ü ✓ " + std::to_string(i);
    if (i % 50 == 7) line += std::string(9000, '\\');  // a large one among them
    sent.push_back(json{{"line", line}}.dump());
    a.hub.publish({"printers", "printer/p"}, "printer", sent.back());
  }
  REQUIRE(on_b.wait([&](const auto& v) { return v.size() == sent.size(); }));
  const auto got = on_b.snapshot();
  for (std::size_t i = 0; i < sent.size(); ++i) CHECK(got[i]["data"].dump() == sent[i]);
  CHECK(a.relay.stats().stored == 4);
}
