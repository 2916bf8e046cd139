// PushChannel, the push socket's client, with a stepped clock and a feed of our own: `connected`
// first, auth (reauthRequired when wrong), history once, progress coalesced and throttled at
// 500 ms × throttle, a change of state always sent and in order (but never two currents within
// 500 ms), events filtered by subscription,
// garbage ignored, and a client that falls behind cut off rather than grow the queue.
#include "server/api/push_channel.hpp"

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <vector>

using namespace salient::server;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

struct Feed : PushFeed {
  int backlogs = 0;
  bool session_open = true;
  std::optional<std::string> user_of_auth(std::string_view auth) const override {
    return auth == "admin:good" && session_open ? std::optional<std::string>("admin") : std::nullopt;
  }
  std::string history(PushCursor& cursor, const PushSubscription&) const override {
    cursor.logs_after = 10;
    return R"({"temps":[],"logs":["Recv: ok"]})";
  }
  std::string backlog(PushCursor& cursor, const PushSubscription& s) const override {
    ++const_cast<Feed*>(this)->backlogs;
    const std::string logs = s.logs ? "[\"Send: N" + std::to_string(++cursor.logs_after) + "\"]" : "[]";
    return "\"temps\":[],\"logs\":" + logs;
  }
};

struct Harness {
  Feed feed;
  PushChannel::Clock::time_point now{std::chrono::seconds(1000)};
  int wakes = 0;
  PushChannel channel;
  explicit Harness(PushLimits limits = {})
      : channel(feed, R"({"connected":{"version":"1.10.0"}})", limits, [this] { return now; }) {
    channel.open([this] { ++wakes; });
  }
  std::vector<json> drain() {
    std::vector<json> out;
    while (auto m = channel.next()) out.push_back(json::parse(*m));
    return out;
  }
  void authenticate() {
    channel.receive(R"({"auth": "admin:good"})");
    drain();
  }
};

std::shared_ptr<const std::string> part(const std::string& text, double completion = 0) {
  return std::make_shared<const std::string>(
      json{{"state", {{"text", text}}}, {"progress", {{"completion", completion}}}}.dump());
}

}  // namespace

TEST_CASE("connected first, a wrong auth is told to log in again, a right one gets history") {
  Harness h;
  auto first = h.drain();
  REQUIRE(first.size() == 1);
  CHECK(first[0]["connected"]["version"] == "1.10.0");
  h.channel.progress(part("Operational"));  // nobody is logged in: nothing for this client
  h.channel.state_changed(part("Printing"));
  h.channel.event("PrintStarted", "{}");
  CHECK(h.drain().empty());
  CHECK(!h.channel.authenticated());

  h.channel.receive(R"({"auth": "admin:stale"})");
  auto reauth = h.drain();
  REQUIRE(reauth.size() == 1);
  CHECK(reauth[0]["reauthRequired"]["reason"] == "stale");
  h.channel.receive(R"({"auth": 42})");
  CHECK(h.drain()[0].contains("reauthRequired"));

  h.channel.receive(R"({"auth": "admin:good"})");
  auto history = h.drain();
  REQUIRE(history.size() == 1);
  CHECK(history[0]["history"]["logs"][0] == "Recv: ok");
  CHECK(h.channel.authenticated());
  CHECK(h.wakes >= 3);  // each answer woke the socket
}

TEST_CASE("garbage is ignored and the channel goes on") {
  Harness h;
  h.drain();
  for (const char* junk : {"", "not json", "[1,2]", "\"auth\"", "{\"throttle\": \"x\"}", "{\"throttle\": 0}",
                           "{\"throttle\": -3}", "{\"subscribe\": 5}", "{\"auth\": null}",
                           "[[[[[[[[[[[[[[[[[[[[]]]]]]]]]]]]]]]]]]]]"})
    h.channel.receive(junk);
  CHECK(h.channel.throttle() == 1);
  h.authenticate();
  CHECK(h.channel.authenticated());
}

TEST_CASE("progress is coalesced and sent at most every 500 ms × throttle, temps and logs ride along") {
  Harness h;
  h.authenticate();  // history counts as the first update
  h.channel.progress(part("Printing", 1));
  CHECK(h.drain().empty());  // too soon after the history
  h.now += 499ms;
  h.channel.progress(part("Printing", 2));
  CHECK(h.drain().empty());
  h.now += 1ms;
  CHECK(h.channel.due());
  auto sent = h.drain();
  REQUIRE(sent.size() == 1);  // the newest only: 1 % was replaced by 2 %
  CHECK(sent[0]["current"]["progress"]["completion"] == 2);
  CHECK(sent[0]["current"]["logs"] == json{"Send: N11"});  // what is new since the history
  CHECK(sent[0]["current"]["state"]["text"] == "Printing");
  CHECK(!h.channel.due());

  h.channel.receive(R"({"throttle": 3})");
  CHECK(h.channel.throttle() == 3);
  h.channel.progress(part("Printing", 3));
  h.now += 1499ms;
  CHECK(h.drain().empty());
  h.now += 1ms;
  CHECK(h.drain().size() == 1);
  h.channel.receive(R"({"throttle": 100000})");
  CHECK(h.channel.throttle() == PushLimits{}.max_throttle);
}

TEST_CASE("a change of state is always sent, in order, whatever the throttle, and progress after it waits") {
  Harness h;
  h.authenticate();
  h.channel.receive(R"({"throttle": 10})");
  h.now += 5s;
  h.channel.progress(part("Printing", 99));
  h.channel.state_changed(part("Finishing", 100));
  h.channel.event("PrinterStateChanged", R"({"state_id":"FINISHING"})");
  h.channel.state_changed(part("Operational"));
  h.channel.event("PrintDone", R"({"time":5})");
  // At most one `current` per 500 ms, as OctoPrint: the second change waits, and the event
  // queued behind it with it.
  auto sent = h.drain();
  REQUIRE(sent.size() == 2);
  CHECK(sent[0]["current"]["state"]["text"] == "Finishing");
  CHECK(sent[1]["event"]["type"] == "PrinterStateChanged");
  h.now += 499ms;
  CHECK(!h.channel.due());
  CHECK(h.drain().empty());
  h.now += 1ms;
  CHECK(h.channel.due());
  sent = h.drain();
  REQUIRE(sent.size() == 2);
  CHECK(sent[0]["current"]["state"]["text"] == "Operational");
  CHECK(sent[1]["event"] == json{{"type", "PrintDone"}, {"payload", {{"time", 5}}}});
  // The 99 % was older than the changes: it is not sent after them.
  h.now += 10s;
  CHECK(h.drain().empty());
  h.channel.state_changed(part("Printing"));  // the next print
  h.channel.progress(part("Printing", 1));
  CHECK(h.drain().size() == 1);  // the change alone: the progress waits its turn
  h.now += 4999ms;
  CHECK(h.drain().empty());  // a change of state restarts the throttle's interval
  h.now += 1ms;
  CHECK(h.drain().size() == 1);
}

TEST_CASE("no two currents less than 500 ms apart, even a change of state right after progress") {
  Harness h;
  h.authenticate();
  h.now += 500ms;
  h.channel.progress(part("Printing", 50));
  REQUIRE(h.drain().size() == 1);
  h.now += 30ms;
  h.channel.state_changed(part("Paused", 50));
  CHECK(h.drain().empty());
  h.now += 469ms;
  CHECK(h.drain().empty());
  h.now += 1ms;
  const auto sent = h.drain();
  REQUIRE(sent.size() == 1);
  CHECK(sent[0]["current"]["state"]["text"] == "Paused");
}

TEST_CASE("subscribe: events by type, state off means no current, logs off means none") {
  Harness h;
  h.authenticate();
  h.channel.receive(R"({"subscribe": {"events": ["PrintDone"], "state": {"logs": false}}})");
  h.channel.event("PrintStarted", "{}");
  h.channel.event("PrintDone", "{}");
  h.channel.state_changed(part("Operational"));
  h.now += 500ms;  // the history sent on login is a current too: the next waits its 500 ms
  auto sent = h.drain();
  REQUIRE(sent.size() == 2);
  CHECK(sent[0]["event"]["type"] == "PrintDone");
  CHECK(sent[1]["current"]["logs"].empty());
  CHECK(!h.channel.wants_logs());
  h.channel.receive(R"({"subscribe": {"state": false, "events": false}})");
  h.channel.state_changed(part("Printing"));
  h.channel.event("PrintDone", "{}");
  h.now += 10s;
  h.channel.progress(part("Printing"));
  CHECK(h.drain().empty());
}

TEST_CASE("a client that falls behind is cut off with a reason, and its queue is freed") {
  PushLimits limits;
  limits.max_queued = 8;
  Harness h(limits);
  h.authenticate();
  for (int i = 0; i < 8; ++i) h.channel.state_changed(part("Printing"));
  CHECK(h.channel.close_reason().empty());
  h.channel.event("PrintDone", "{}");  // the ninth
  CHECK(h.channel.close_reason().find("too slow") != std::string::npos);
  CHECK(h.channel.due());  // so that the hub wakes the socket, which closes it
  CHECK(!h.channel.next());
  h.channel.closed();
  h.channel.state_changed(part("Operational"));  // after the close: dropped, no growth
  CHECK(!h.channel.next());
}

TEST_CASE("a session that ends (a logout, a revoked key) is told reauthRequired and gets nothing more") {
  Harness h;
  h.authenticate();
  h.channel.recheck_session();  // still open: nothing to say
  CHECK(h.drain().empty());
  h.feed.session_open = false;
  h.channel.recheck_session();
  auto sent = h.drain();
  REQUIRE(sent.size() == 1);
  CHECK(sent[0]["reauthRequired"]["reason"] == "removed");
  CHECK(!h.channel.authenticated());
  h.channel.state_changed(part("Printing"));
  h.channel.event("PrintStarted", "{}");
  CHECK(h.drain().empty());
  h.channel.recheck_session();  // told once
  CHECK(h.drain().empty());
}
