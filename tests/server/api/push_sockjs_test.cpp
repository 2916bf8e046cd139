// SockJS's framing around a channel: "o" first, messages batched as a["…"] JSON strings, "h" when
// silent, client frames ["…"] unpacked; and which paths are SockJS WebSocket endpoints.
#include "server/api/push_sockjs.hpp"

#include <doctest/doctest.h>

#include <deque>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

using namespace salient::server;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

struct Echo : WebSocketChannel {
  std::deque<std::string> out;
  std::vector<std::string> in;
  bool was_closed = false;
  void open(std::function<void()>) override {}
  void receive(const std::string& text) override { in.push_back(text); }
  std::optional<std::string> next() override {
    if (out.empty()) return std::nullopt;
    std::string m = out.front();
    out.pop_front();
    return m;
  }
  std::string close_reason() override { return {}; }
  void closed() override { was_closed = true; }
};

}  // namespace

TEST_CASE("SockJS frames: o, a[…] of JSON strings, h when silent, client arrays unpacked") {
  auto inner = std::make_shared<Echo>();
  SockJsChannel s(inner, 50ms);
  inner->out = {R"({"connected":{}})", R"({"history":{"a":"\"q\""}})"};
  CHECK(s.next() == "o");
  const std::optional<std::string> batch = s.next();
  REQUIRE(batch);
  REQUIRE(batch->front() == 'a');
  const json messages = json::parse(batch->substr(1));
  REQUIRE(messages.size() == 2);  // both in one frame
  CHECK(json::parse(messages[0].get<std::string>()).contains("connected"));
  CHECK(json::parse(messages[1].get<std::string>())["history"]["a"] == "\"q\"");
  CHECK(!s.next());
  CHECK(!s.heartbeat_due());
  std::this_thread::sleep_for(60ms);
  CHECK(s.heartbeat_due());
  CHECK(s.next() == "h");
  CHECK(!s.next());

  s.receive(R"(["{\"auth\": \"a:b\"}", "{\"throttle\": 2}"])");
  s.receive(R"("{\"throttle\": 3}")");
  s.receive("not json");
  s.receive("[1, {\"x\": 2}]");
  CHECK(inner->in ==
        std::vector<std::string>{R"({"auth": "a:b"})", R"({"throttle": 2})", R"({"throttle": 3})"});
  s.closed();
  CHECK(inner->was_closed);
}

TEST_CASE("SockJS WebSocket paths: /sockjs/{server}/{session}/websocket, ids without dots or slashes") {
  CHECK(is_sockjs_websocket_path("/sockjs/012/abcdef/websocket"));
  CHECK(is_sockjs_websocket_path("/sockjs/1/x/websocket"));
  CHECK(!is_sockjs_websocket_path("/sockjs/websocket"));
  CHECK(!is_sockjs_websocket_path("/sockjs/012/websocket"));
  CHECK(!is_sockjs_websocket_path("/sockjs//abc/websocket"));
  CHECK(!is_sockjs_websocket_path("/sockjs/012/a.b/websocket"));
  CHECK(!is_sockjs_websocket_path("/sockjs/012/a/b/websocket"));
  CHECK(!is_sockjs_websocket_path("/sockjs/012/abc/xhr"));
  CHECK(!is_sockjs_websocket_path("/other/012/abc/websocket"));
}
