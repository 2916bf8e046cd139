// HttpServer: HTTP/1.1 with keep-alive on Boost.Beast (the only file that includes it is the
// .cpp), and WebSocket through a WebSocketChannel. One strand per connection; limits on
// connections (in all and per address), header size, body size and bodies in flight; the key is
// checked on the headers, before any body is read; a timeout per read and write without
// progress; accepting goes on after descriptors run out; and a graceful stop: no new
// connections, responses in flight are finished, idle connections are closed.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "server/http/client_address.hpp"
#include "server/http/router.hpp"
#include "server/http/websocket_channel.hpp"

namespace salient::server {

struct HttpServerOptions {
  std::string address = "127.0.0.1";
  unsigned short port = 8080;  // 0: any free port (see start())
  std::size_t body_limit = 64u << 20;
  std::chrono::seconds timeout{30};  // per read or write that makes no progress
  int threads = 2;
  // Beyond these a new connection is answered 503 and closed, with a log line.
  std::size_t max_connections = 512, max_connections_per_address = 64;
  // Bodies being read at once (each counts its Content-Length, or body_limit when chunked): a
  // request beyond the budget gets 503 with Retry-After before its body is read.
  std::size_t max_bodies_in_flight = 256u << 20;
  std::function<void(const std::string&)> log;  // one line, for the daemon's log
  // Called after each response: method (one of the HTTP verbs, or "OTHER"), route name, status,
  // seconds, the client's address (for logs and metrics).
  std::function<void(const std::string&, const std::string&, int, double, const std::string&)> on_response;
  // Behind a reverse proxy: whose X-Forwarded-* headers are believed, and the path prefix
  // Location headers get when no trusted proxy names one (client_address.hpp).
  TrustedProxies trusted_proxies;
  std::string base_path;
  // Upgrade requests by path: exact ("/api/v1/events", "/sockjs/websocket"), or a prefix when
  // the key ends with "/*" ("/sockjs/*": the acceptor checks the rest; an exact key wins, then
  // the longest prefix). An upgrade to any other path is served as a plain HTTP request (the
  // router's 404, or its 426 route).
  std::map<std::string, WebSocketAcceptor> websockets;
};

class HttpServer {
 public:
  HttpServer(HttpServerOptions options, const Router& router);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  unsigned short start();  // binds and listens; returns the port; throws std::runtime_error
  void run();              // serves on `threads` threads until stop() has drained everything
  void stop();             // from any thread, or a signal watcher

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace salient::server
