// The WebSocket /api/v1/events on the real server with the daemon's acceptor and a real key: a
// browser, which cannot send headers on a WebSocket, offers the key as the subprotocol
// "salient-key.KEY"; the server accepts it, answers with the plain protocol it was offered (never
// echoing the key), and refuses a wrong one with 401. Nothing it logs holds the key.
#include <doctest/doctest.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "server/api/routes.hpp"
#include "server/http/http_server.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;

namespace {

struct Daemon {
  salient::test::ScratchDir dir{"event-routes"};
  std::unique_ptr<Store> store;
  std::string key;
  std::unique_ptr<ApiKeys> keys;
  EventHub hub;
  Router router;
  std::unique_ptr<HttpServer> server;
  std::thread thread;
  unsigned short port = 0;
  std::mutex log_mutex;
  std::string log;

  Daemon() {
    store = std::make_unique<Store>(dir.path);
    key = ensure_api_key(*store).key;
    keys = std::make_unique<ApiKeys>(*store);
    router.set_authenticator([this](const HttpRequest& r) { return keys->authenticate(r); });
    add_event_route(router);
    HttpServerOptions options;
    options.port = 0;
    options.websockets["/api/v1/events"] = events_endpoint(hub, *keys);
    options.log = [this](const std::string& line) {
      std::lock_guard lock(log_mutex);
      log += line + "\n";
    };
    server = std::make_unique<HttpServer>(options, router);
    port = server->start();
    thread = std::thread([this] { server->run(); });
  }
  ~Daemon() {
    server->stop();
    thread.join();
  }
};

struct Client {
  asio::io_context io;
  websocket::stream<beast::tcp_stream> ws{io};
  websocket::response_type response;
  beast::error_code connect(unsigned short port, const std::string& protocols) {
    beast::get_lowest_layer(ws).connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    ws.set_option(websocket::stream_base::decorator([protocols](websocket::request_type& r) {
      r.set(beast::http::field::sec_websocket_protocol, protocols);
    }));
    beast::error_code ec;
    ws.handshake(response, "127.0.0.1", "/api/v1/events", ec);
    return ec;
  }
};

}  // namespace

TEST_CASE("a browser's key in the subprotocol opens the events, and the answer does not echo it") {
  Daemon d;
  REQUIRE(d.key.size() == 43);  // 32 random bytes, URL-safe base64
  Client c;
  REQUIRE(!c.connect(d.port, "salient.v1, salient-key." + d.key));
  CHECK(c.response.result_int() == 101);
  CHECK(std::string(c.response[beast::http::field::sec_websocket_protocol]) == "salient.v1");
  c.ws.write(asio::buffer(std::string(R"({"subscribe": ["jobs"]})")));
  beast::flat_buffer in;
  c.ws.read(in);
  CHECK(nlohmann::json::parse(beast::buffers_to_string(in.data()))["type"] == "subscribed");
  c.ws.close(websocket::close_code::normal);
  std::lock_guard lock(d.log_mutex);
  CHECK(d.log.find(d.key) == std::string::npos);
}

TEST_CASE("offered alone, the key's protocol is the one chosen (a browser needs one back)") {
  Daemon d;
  Client c;
  REQUIRE(!c.connect(d.port, "salient-key." + d.key));
  CHECK(std::string(c.response[beast::http::field::sec_websocket_protocol]) == "salient-key." + d.key);
}

// The status line that answers an upgrade offering these protocols.
std::string upgrade_status(unsigned short port, const std::string& protocols) {
  asio::io_context io;
  asio::ip::tcp::socket socket(io);
  socket.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  const std::string request =
      "GET /api/v1/events HTTP/1.1\r\nHost: t\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n"
      "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Protocol: " +
      protocols + "\r\n\r\n";
  asio::write(socket, asio::buffer(request));
  std::string in;
  beast::error_code ec;
  asio::read_until(socket, asio::dynamic_buffer(in), "\r\n", ec);
  return in.substr(0, in.find("\r\n"));
}

TEST_CASE("a wrong key in the subprotocol is refused with 401, as a wrong header is") {
  Daemon d;
  CHECK(upgrade_status(d.port, "salient.v1, salient-key.0123456789abcdef").rfind("HTTP/1.1 401", 0) == 0);
  CHECK(upgrade_status(d.port, "salient.v1").rfind("HTTP/1.1 401", 0) == 0);
  CHECK(upgrade_status(d.port, "salient.v1, salient-key." + d.key).rfind("HTTP/1.1 101", 0) == 0);
  Client c;
  CHECK(c.connect(d.port, "salient.v1, salient-key.0123456789abcdef"));  // Beast's client sees it too
}

// Issue 32: a WebSocket kept streaming 70 s after its key was revoked. Revoked through another
// node's keys (a second ApiKeys on the store), the connection it opened is closed within a second.
TEST_CASE("a key revoked on another node closes the events it opened within a second") {
  Daemon d;
  d.keys->start_refresh(std::chrono::milliseconds(100), {});
  const NewKey otto = d.keys->create("otto", Role::viewer, "phone");
  Client c;
  REQUIRE(!c.connect(d.port, "salient.v1, salient-key." + otto.key));
  c.ws.write(asio::buffer(std::string(R"({"subscribe": ["jobs"]})")));
  beast::flat_buffer in;
  c.ws.read(in);
  in.consume(in.size());
  // A read that never ends fails the test instead of hanging it.
  const timeval limit{3, 0};
  ::setsockopt(beast::get_lowest_layer(c.ws).socket().native_handle(), SOL_SOCKET, SO_RCVTIMEO, &limit,
               sizeof limit);

  ApiKeys other_node(*d.store);
  other_node.revoke(otto.info.id);
  const auto revoked = std::chrono::steady_clock::now();
  beast::error_code ec;
  while (!ec) {
    c.ws.read(in, ec);
    in.consume(in.size());
  }
  const auto took = std::chrono::steady_clock::now() - revoked;
  CHECK(ec == websocket::error::closed);
  CHECK(took < std::chrono::seconds(1));
  CHECK(c.ws.reason().code == websocket::close_code::policy_error);
  const auto& why = c.ws.reason().reason;
  CHECK(std::string(why.data(), why.size()).find("revoked") != std::string::npos);
  CHECK(upgrade_status(d.port, "salient.v1, salient-key." + otto.key).rfind("HTTP/1.1 401", 0) == 0);
  d.keys->stop_refresh();
}
