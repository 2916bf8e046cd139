// The Beast server on loopback, spoken to through a plain socket: what curl would see.
#include <arpa/inet.h>
#include <doctest/doctest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>
#include <thread>

#include "server/http/http_server.hpp"

using namespace salient::server;

namespace {

int connect_to(unsigned short port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  return fd;
}

void send_all(int fd, const std::string& bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return;  // the server may close early (413)
    done += static_cast<std::size_t>(n);
  }
}

// Reads one response (headers + Content-Length body).
std::string read_response(int fd) {
  std::string in;
  char buf[4096];
  for (;;) {
    const std::size_t end = in.find("\r\n\r\n");
    if (end != std::string::npos) {
      const std::size_t cl = in.find("Content-Length: ");
      const std::size_t length = cl == std::string::npos ? 0 : std::stoul(in.substr(cl + 16));
      if (in.size() >= end + 4 + length) return in.substr(0, end + 4 + length);
    }
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) return in;
    in.append(buf, static_cast<std::size_t>(n));
  }
}

struct Running {
  Router router;
  HttpServerOptions options;
  std::unique_ptr<HttpServer> server;
  std::thread thread;
  unsigned short port = 0;
  explicit Running(std::size_t body_limit = 1 << 20) {
    router.add("GET", "/hello/{who}", Access::open,
               [](const HttpRequest& r, const PathParams& p) { return HttpResponse::text(200, "hello " + p.at("who") + (r.query.count("x") ? r.query.at("x") : "")); });
    router.add("POST", "/echo", Access::open, [](const HttpRequest& r, const PathParams&) { return HttpResponse::text(200, r.body); });
    options.port = 0;
    options.body_limit = body_limit;
    server = std::make_unique<HttpServer>(options, router);
    port = server->start();
    thread = std::thread([this] { server->run(); });
  }
  ~Running() {
    server->stop();
    thread.join();
  }
};

}  // namespace

TEST_CASE("keep-alive: several requests on one connection, each answered in order") {
  Running s;
  const int fd = connect_to(s.port);
  send_all(fd, "GET /hello/world?x=! HTTP/1.1\r\nHost: t\r\n\r\n");
  const std::string first = read_response(fd);
  CHECK(first.rfind("HTTP/1.1 200 OK", 0) == 0);
  CHECK(first.find("\r\n\r\nhello world!") != std::string::npos);
  send_all(fd, "POST /echo HTTP/1.1\r\nHost: t\r\nContent-Length: 5\r\n\r\nabcde");
  CHECK(read_response(fd).find("\r\n\r\nabcde") != std::string::npos);
  send_all(fd, "GET /nowhere HTTP/1.1\r\nHost: t\r\n\r\n");
  const std::string missing = read_response(fd);
  CHECK(missing.rfind("HTTP/1.1 404", 0) == 0);
  CHECK(missing.find("application/json") != std::string::npos);
  ::close(fd);
}

TEST_CASE("a body over the limit is 413, a malformed request 400, both as JSON") {
  Running s(1000);
  int fd = connect_to(s.port);
  send_all(fd, "POST /echo HTTP/1.1\r\nHost: t\r\nContent-Length: 5000\r\n\r\n" + std::string(5000, 'x'));
  const std::string big = read_response(fd);
  CHECK(big.rfind("HTTP/1.1 413", 0) == 0);
  CHECK(big.find("\"code\":\"too_large\"") != std::string::npos);
  ::close(fd);
  fd = connect_to(s.port);
  send_all(fd, "BREW /pot HTCPCP/1.0\r\n\r\n");
  CHECK(read_response(fd).rfind("HTTP/1.1 400", 0) == 0);
  ::close(fd);
  fd = connect_to(s.port);
  send_all(fd, "GET /hello/%zz HTTP/1.1\r\nHost: t\r\n\r\n");
  CHECK(read_response(fd).rfind("HTTP/1.1 400", 0) == 0);
  ::close(fd);
}

TEST_CASE("stop: idle keep-alive connections are closed and run() returns") {
  auto s = std::make_unique<Running>();
  const int fd = connect_to(s->port);
  send_all(fd, "GET /hello/a HTTP/1.1\r\nHost: t\r\n\r\n");
  CHECK(read_response(fd).rfind("HTTP/1.1 200", 0) == 0);
  s.reset();  // stop() and join: must not hang on the idle connection
  char c;
  CHECK(::recv(fd, &c, 1, 0) == 0);  // the server closed it
  ::close(fd);
}
