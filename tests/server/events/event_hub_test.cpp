// The event hub's promises: subscribers get what they asked for, once; progress coalesces and
// may be dropped; state changes are never dropped (a client too far behind is cut off instead).
#include "server/events/event_hub.hpp"

#include <doctest/doctest.h>

#include <atomic>
#include <nlohmann/json.hpp>
#include <thread>

using namespace salient::server;
using nlohmann::json;

namespace {

std::vector<json> drain(Subscription& s) {
  std::vector<json> out;
  while (auto m = s.next()) out.push_back(json::parse(*m));
  return out;
}

}  // namespace

TEST_CASE("topics: only the documented ones, with safe ids") {
  for (const char* t : {"jobs", "printers", "job/j0123abc", "printer/sim", "terminal/my-printer_2"})
    CHECK_MESSAGE(EventHub::valid_topic(t), t);
  for (const char* t : {"", "job/", "jobs/x", "printer/../etc", "terminal/a b", "everything", "job/\"x"})
    CHECK_MESSAGE(!EventHub::valid_topic(t), t);
}

TEST_CASE("an event reaches each subscriber of any of its topics, once, with type, topic, time and data") {
  EventHub hub;
  auto a = hub.subscribe(), b = hub.subscribe(), c = hub.subscribe();
  REQUIRE(a->subscribe("jobs"));
  REQUIRE(a->subscribe("job/j1"));  // both topics of the event: still once
  REQUIRE(b->subscribe("job/j1"));
  REQUIRE(c->subscribe("job/j2"));
  hub.publish({"jobs", "job/j1"}, "job", R"({"id":"j1","state":"queued"})");
  const auto got_a = drain(*a), got_b = drain(*b), got_c = drain(*c);
  REQUIRE(got_a.size() == 1);
  REQUIRE(got_b.size() == 1);
  CHECK(got_c.empty());
  CHECK(got_a[0]["type"] == "job");
  CHECK(got_a[0]["topic"] == "job/j1");
  CHECK(got_a[0]["data"]["state"] == "queued");
  CHECK(got_a[0]["time"].get<double>() > 1.6e9);
}

TEST_CASE("each subscriber gets an event under a topic it asked for, so that it can filter on it") {
  EventHub hub;
  auto all = hub.subscribe(), one = hub.subscribe(), both = hub.subscribe(), printers = hub.subscribe();
  REQUIRE(all->subscribe("jobs"));
  REQUIRE(one->subscribe("job/j1"));
  REQUIRE(both->subscribe("jobs"));
  REQUIRE(both->subscribe("job/j1"));
  REQUIRE(printers->subscribe("printers"));
  hub.publish({"jobs", "job/j1"}, "job", R"({"id":"j1","state":"queued"})");
  hub.publish({"jobs", "job/j1"}, "job", R"({"id":"j1","progress":0.1})", Delivery::coalesce);
  hub.publish({"jobs", "job/j1"}, "job", R"({"id":"j1","progress":0.2})",
              Delivery::coalesce);  // replaces 0.1
  hub.publish({"printers", "printer/p1"}, "queue", R"({"printer":"p1"})");
  const auto got_all = drain(*all), got_one = drain(*one), got_both = drain(*both), got_p = drain(*printers);
  REQUIRE(got_all.size() == 2);
  REQUIRE(got_one.size() == 2);
  REQUIRE(got_both.size() == 2);
  REQUIRE(got_p.size() == 1);
  for (const json& m : got_all) CHECK(m["topic"] == "jobs");
  for (const json& m : got_one) CHECK(m["topic"] == "job/j1");
  for (const json& m : got_both) CHECK(m["topic"] == "job/j1");  // the most precise it asked for
  CHECK(got_p[0]["topic"] == "printers");
  CHECK(got_all[1]["data"]["progress"] == 0.2);
  CHECK(got_all[0]["time"] == got_one[0]["time"]);  // one event, one time, whatever the topic
}

TEST_CASE("progress coalesces behind a state change but never jumps over it") {
  EventHub hub;
  auto s = hub.subscribe();
  REQUIRE(s->subscribe("job/j1"));
  hub.publish({"job/j1"}, "job", R"({"p":1})", Delivery::coalesce);
  hub.publish({"job/j1"}, "job", R"({"p":2})", Delivery::coalesce);  // replaces p1
  hub.publish({"job/j1"}, "job", R"({"phase":"plan"})");             // a state change
  hub.publish({"job/j1"}, "job", R"({"p":3})", Delivery::coalesce);  // after it, not merged into p2
  hub.publish({"job/j1"}, "job", R"({"p":4})", Delivery::coalesce);  // replaces p3
  const auto got = drain(*s);
  REQUIRE(got.size() == 3);
  CHECK(got[0]["data"]["p"] == 2);
  CHECK(got[1]["data"]["phase"] == "plan");
  CHECK(got[2]["data"]["p"] == 4);
}

TEST_CASE("a slow client loses progress and terminal lines past the limit, never a state change") {
  EventHub hub({/*progress_limit=*/8, /*state_limit=*/1000});
  auto s = hub.subscribe();
  REQUIRE(s->subscribe("jobs"));
  REQUIRE(s->subscribe("terminal/sim"));
  for (int i = 0; i < 100; ++i) {
    hub.publish({"jobs", "job/j" + std::to_string(i)}, "job", "{\"n\":" + std::to_string(i) + "}");
    hub.publish({"terminal/sim"}, "terminal", "{\"t\":" + std::to_string(i) + "}", Delivery::best_effort);
  }
  const auto got = drain(*s);
  int states = 0, lines = 0;
  for (const auto& m : got) (m["type"] == "job" ? states : lines) += 1;
  CHECK(states == 100);
  CHECK(lines < 100);
  CHECK(s->dropped() == static_cast<std::size_t>(100 - lines));
  CHECK(s->close_reason().empty());
}

TEST_CASE("past the state limit the client is cut off with a reason instead of missing a change") {
  EventHub hub({8, 16});
  auto s = hub.subscribe();
  REQUIRE(s->subscribe("jobs"));
  for (int i = 0; i < 17; ++i) hub.publish({"jobs", "job/j"}, "job", "{}");
  CHECK(s->close_reason().find("too slow") != std::string::npos);
  CHECK(!s->next());
}

TEST_CASE(
    "a new subscriber gets the topic's snapshot first, then 'subscribed', and bad messages get an error") {
  EventHub hub;
  hub.set_snapshot([](const std::string& topic) {
    std::vector<std::pair<std::string, std::string>> out;
    if (topic == "job/j1") out.emplace_back("job", R"({"id":"j1","state":"running"})");
    return out;
  });
  auto s = hub.subscribe();
  s->receive(R"({"subscribe": ["job/j1", "printers"]})");
  auto got = drain(*s);
  REQUIRE(got.size() == 2);
  CHECK(got[0]["data"]["state"] == "running");
  CHECK(got[0]["topic"] == "job/j1");
  CHECK(got[1]["type"] == "subscribed");
  CHECK(got[1]["data"]["topics"].size() == 2);
  // Every message has the four fields; a reply about the connection has a null topic.
  for (const json& m : got) CHECK(m.size() == 4);
  CHECK(got[1].contains("topic"));
  CHECK(got[1]["topic"].is_null());
  for (const char* bad :
       {"not json", "[1]", R"({"subscribe": "jobs"})", R"({"subscribe": ["nope"]})", R"({"listen": []})"}) {
    s->receive(bad);
    got = drain(*s);
    REQUIRE_MESSAGE(got.size() == 1, bad);
    CHECK(got[0]["type"] == "error");
    CHECK(got[0]["topic"].is_null());
    CHECK(!got[0]["data"]["message"].get<std::string>().empty());
  }
  s->receive(R"({"unsubscribe": ["printers"]})");
  got = drain(*s);
  CHECK(got.back()["data"]["topics"] == json::array({"job/j1"}));
}

TEST_CASE("publishers on many threads: each subscriber sees every state change, in each publisher's order") {
  EventHub hub;
  std::vector<std::shared_ptr<Subscription>> subs;
  std::atomic<int> wakes{0};
  for (int i = 0; i < 20; ++i) {
    subs.push_back(hub.subscribe([&] { ++wakes; }));
    REQUIRE(subs.back()->subscribe("jobs"));
  }
  std::vector<std::thread> publishers;
  for (int t = 0; t < 4; ++t)
    publishers.emplace_back([&, t] {
      for (int i = 0; i < 500; ++i)
        hub.publish({"jobs", "job/t" + std::to_string(t)}, "job",
                    "{\"t\":" + std::to_string(t) + ",\"i\":" + std::to_string(i) + "}");
    });
  for (auto& p : publishers) p.join();
  for (auto& s : subs) {
    std::vector<int> last(4, -1);
    int n = 0;
    for (const auto& m : drain(*s)) {
      const int t = m["data"]["t"], i = m["data"]["i"];
      CHECK(i == last[static_cast<std::size_t>(t)] + 1);
      last[static_cast<std::size_t>(t)] = i;
      ++n;
    }
    CHECK(n == 2000);
  }
  CHECK(wakes > 0);
  subs.front()->closed();
  CHECK(hub.subscribers() == 19);
}

TEST_CASE("a subscribe list is folded, and replies and snapshots count against the client's bound") {
  EventHub hub({8, 64});
  int snapshots = 0;
  hub.set_snapshot([&](const std::string& topic) {
    ++snapshots;
    return std::vector<std::pair<std::string, std::string>>{{"printer", "{\"id\":\"" + topic + "\"}"}};
  });
  auto s = hub.subscribe();
  json many = json::array();
  for (int i = 0; i < 5200; ++i) many.push_back("printers");
  s->receive(json{{"subscribe", many}}.dump());
  CHECK(snapshots == 1);     // one topic, one snapshot
  CHECK(s->pending() == 2);  // that snapshot and the reply
  s->receive(json{{"subscribe", {"printers"}}}.dump());
  CHECK(snapshots == 1);  // subscribed already: no second snapshot
  for (int i = 0; i < 100 && s->close_reason().empty(); ++i) s->receive(R"({"subscribe": ["printers"]})");
  CHECK(s->close_reason().find("too slow") != std::string::npos);  // never read: cut off, not grown
  CHECK(s->pending() == 0);
  // Bytes count too: a few big state changes fill the byte bound before the count bound.
  EventHubOptions small;
  small.byte_limit = 1 << 16;
  EventHub bytes(small);
  auto b = bytes.subscribe();
  REQUIRE(b->subscribe("jobs"));
  const std::string big = "\"" + std::string(20000, 'x') + "\"";
  for (int i = 0; i < 5; ++i) bytes.publish({"jobs", "job/j"}, "job", big);
  CHECK(b->close_reason().find("MiB waiting") != std::string::npos);
}

TEST_CASE("deep or broken subscription messages are refused while parsing, and any bytes echo safely") {
  EventHub hub;
  auto s = hub.subscribe();
  s->receive(std::string(80000, '[') + std::string(80000, ']'));
  auto got = drain(*s);
  REQUIRE(got.size() == 1);
  CHECK(got[0]["data"]["message"].get<std::string>().find("nested deeper") != std::string::npos);
  s->receive("{\"subscribe\": [\"job/\xff\xfe\"]}");
  s->receive("{\"\xc0\xaf\": 1}");
  CHECK(drain(*s).size() == 2);  // both errors are valid JSON (drain parses them)
}
