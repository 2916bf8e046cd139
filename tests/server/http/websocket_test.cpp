// WebSocket on the Beast server, with a Beast client on loopback: the upgrade refused as an HTTP
// error, subscription by message, events delivered, and a graceful stop that closes the stream
// with "going away".
#include <doctest/doctest.h>

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "server/events/event_hub.hpp"
#include "server/http/http_server.hpp"

using namespace salient::server;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using nlohmann::json;

namespace {

// Says who accepted it, once.
struct Named : WebSocketChannel {
  explicit Named(std::string n) : name(std::move(n)) {}
  std::string name;
  bool said = false;
  void open(std::function<void()> wake) override { wake(); }
  void receive(const std::string&) override {}
  std::optional<std::string> next() override {
    if (said) return std::nullopt;
    said = true;
    return json{{"by", name}}.dump();
  }
  std::string close_reason() override { return {}; }
  void closed() override {}
};

struct Running {
  Router router;
  EventHub hub;
  std::unique_ptr<HttpServer> server;
  std::thread thread;
  unsigned short port = 0;
  Running() {
    HttpServerOptions options;
    options.port = 0;
    options.websockets["/events"] = [this](const HttpRequest& r) -> WebSocketAccept {
      if (r.header("x-api-key") != "k") return {nullptr, error_response(401, "unauthorized", "key")};
      return {hub.subscribe(), {}};
    };
    options.websockets["/pre/*"] = [](const HttpRequest& r) -> WebSocketAccept {
      return {std::make_shared<Named>("prefix " + r.path), {}};
    };
    options.websockets["/pre/deeper/*"] = [](const HttpRequest& r) -> WebSocketAccept {
      return {std::make_shared<Named>("deeper " + r.path), {}};
    };
    options.websockets["/pre/exact"] = [](const HttpRequest&) -> WebSocketAccept {
      return {std::make_shared<Named>("exact"), {}};
    };
    server = std::make_unique<HttpServer>(options, router);
    port = server->start();
    thread = std::thread([this] { server->run(); });
  }
  void stop() {
    if (!thread.joinable()) return;
    server->stop();
    thread.join();
  }
  ~Running() { stop(); }
};

struct Client {
  asio::io_context io;
  websocket::stream<beast::tcp_stream> ws{io};
  beast::flat_buffer buffer;
  websocket::response_type response;
  beast::error_code connect(unsigned short port, const std::string& path, const std::string& key) {
    beast::get_lowest_layer(ws).connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    ws.set_option(
        websocket::stream_base::decorator([key](websocket::request_type& r) { r.set("X-Api-Key", key); }));
    beast::error_code ec;
    ws.handshake(response, "127.0.0.1", path, ec);
    return ec;
  }
  json read() {
    ws.read(buffer);
    json j = json::parse(beast::buffers_to_string(buffer.data()));
    buffer.consume(buffer.size());
    return j;
  }
};

}  // namespace

// The upgrade request as bytes, and the status line of the answer.
std::string upgrade_status(unsigned short port, const std::string& path, const std::string& key) {
  asio::io_context io;
  asio::ip::tcp::socket socket(io);
  socket.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  const std::string request =
      "GET " + path +
      " HTTP/1.1\r\nHost: t\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n"
      "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nX-Api-Key: " +
      key + "\r\n\r\n";
  asio::write(socket, asio::buffer(request));
  std::string in;
  beast::error_code ec;
  asio::read_until(socket, asio::dynamic_buffer(in), "\r\n", ec);
  return in.substr(0, in.find("\r\n"));
}

TEST_CASE("an upgrade without the key is refused with the HTTP status, a wrong path is 404") {
  Running s;
  CHECK(upgrade_status(s.port, "/events", "wrong").rfind("HTTP/1.1 401", 0) == 0);
  CHECK(upgrade_status(s.port, "/elsewhere", "k").rfind("HTTP/1.1 404", 0) == 0);
  CHECK(upgrade_status(s.port, "/events", "k").rfind("HTTP/1.1 101", 0) == 0);
  Client c;
  CHECK(c.connect(s.port, "/events", "wrong"));  // Beast's client sees the refusal too
}

TEST_CASE("upgrades dispatch by path: exact first, then the longest prefix, others are plain HTTP") {
  Running s;
  const auto by = [&](const std::string& path) {
    Client c;
    REQUIRE(!c.connect(s.port, path, "k"));
    return c.read()["by"].get<std::string>();
  };
  CHECK(by("/pre/exact") == "exact");
  CHECK(by("/pre/a/b") == "prefix /pre/a/b");
  CHECK(by("/pre/deeper/x") == "deeper /pre/deeper/x");
  CHECK(by("/pre/exactly") == "prefix /pre/exactly");
  CHECK(upgrade_status(s.port, "/pre", "k").rfind("HTTP/1.1 404", 0) ==
        0);  // the prefix alone is not under it
  CHECK(upgrade_status(s.port, "/pre/", "k").rfind("HTTP/1.1 404", 0) == 0);  // nor is nothing after it
}

TEST_CASE("subscribe by message, receive events in order, and a graceful stop closes with going away") {
  Running s;
  Client c;
  REQUIRE(!c.connect(s.port, "/events", "k"));
  c.ws.write(asio::buffer(std::string(R"({"subscribe": ["jobs"]})")));
  CHECK(c.read()["type"] == "subscribed");
  for (int i = 0; i < 200; ++i) s.hub.publish({"jobs", "job/j"}, "job", "{\"i\":" + std::to_string(i) + "}");
  for (int i = 0; i < 200; ++i) REQUIRE(c.read()["data"]["i"] == i);
  std::thread stopper([&] { s.stop(); });  // it waits for the client's half of the close handshake
  beast::error_code ec;
  c.ws.read(c.buffer, ec);
  stopper.join();
  CHECK(ec == websocket::error::closed);
  CHECK(c.ws.reason().code == websocket::close_code::going_away);
}

TEST_CASE("a client that leaves is forgotten by the hub") {
  Running s;
  {
    Client c;
    REQUIRE(!c.connect(s.port, "/events", "k"));
    c.ws.write(asio::buffer(std::string(R"({"subscribe": ["printers"]})")));
    CHECK(c.read()["type"] == "subscribed");
    CHECK(s.hub.subscribers() == 1);
    c.ws.close(websocket::close_code::normal);
  }
  for (int i = 0; i < 200 && s.hub.subscribers() > 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  CHECK(s.hub.subscribers() == 0);
}
