#include "server/http/http_server.hpp"

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <thread>
#include <vector>

#include "server/http/http_shared.hpp"

namespace salient::server {

using namespace http_internal;

struct HttpServer::Impl {
  Impl(HttpServerOptions options, const Router& router)
      : shared{router, std::move(options)},
        io(std::max(1, shared.options.threads)),
        acceptor(asio::make_strand(io)),
        retry(acceptor.get_executor()),
        sweeper(acceptor.get_executor()) {}

  // Every few seconds, sessions whose socket is gone without a handler to notice are dropped.
  void sweep_later() {
    sweeper.expires_after(std::chrono::seconds(5));
    sweeper.async_wait([this](boost::system::error_code ec) {
      if (ec) return;
      std::set<std::shared_ptr<Session>> sessions;
      {
        std::lock_guard lock(shared.mutex);
        if (shared.stopping) return;
        sessions = shared.sessions;
      }
      for (const auto& s : sessions) sweep_session(s);
      sweep_later();
    });
  }

  void accept() {
    acceptor.async_accept(asio::make_strand(io), [this](boost::system::error_code ec, tcp::socket socket) {
      on_accept(ec, std::move(socket));
    });
  }

  void on_accept(boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;  // closed by stop()
    {
      std::lock_guard lock(shared.mutex);
      if (shared.stopping) return;
    }
    if (ec) return accept_later(ec);
    if (backoff.count() > 0) shared.log("http accepting again");
    backoff = std::chrono::milliseconds(0);
    set_cloexec(socket.native_handle());
    boost::system::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);  // a small reply must not wait 40 ms for Nagle
    const std::string address = socket.remote_endpoint(ignored).address().to_string();
    std::string why;
    if (auto slot = ConnectionSlot::take(shared, address, why))
      start_session(std::move(socket), shared, std::move(slot));
    else
      refuse(std::move(socket), why);
    accept();
  }

  // Out of descriptors (or memory): the pending connection stays in the backlog; try again soon
  // rather than give up accepting for good.
  void accept_later(boost::system::error_code ec) {
    if (backoff.count() == 0) shared.log("http accept failed (" + ec.message() + "): retrying with back-off");
    backoff = std::clamp(backoff * 2, std::chrono::milliseconds(50), std::chrono::milliseconds(1000));
    retry.expires_after(backoff);
    retry.async_wait([this](boost::system::error_code wait) {
      if (!wait) accept();
    });
  }

  void refuse(tcp::socket socket, const std::string& why) {
    static const std::string body =
        R"({"error":{"code":"busy","message":"too many connections: try again shortly"}})";
    static const std::string reply =
        "HTTP/1.1 503 Service Unavailable\r\nServer: salientd\r\nContent-Type: "
        "application/json\r\nRetry-After: 5\r\nConnection: close\r\nContent-Length: " +
        std::to_string(body.size()) + "\r\n\r\n" + body;
    {
      std::lock_guard lock(shared.limits_mutex);
      ++shared.refused_since_log;
      if (Clock::now() - shared.last_refusal_log >= std::chrono::seconds(10)) {
        shared.log("http refusing connections: " + why + " is reached; " +
                   std::to_string(shared.refused_since_log) + " refused (503) since the last such line");
        shared.refused_since_log = 0;
        shared.last_refusal_log = Clock::now();
      }
    }
    boost::system::error_code ignored;
    socket.non_blocking(true, ignored);
    socket.write_some(asio::buffer(reply), ignored);
    socket.shutdown(tcp::socket::shutdown_both, ignored);
    socket.close(ignored);
  }

  Shared shared;
  asio::io_context io;
  tcp::acceptor acceptor;
  asio::steady_timer retry, sweeper;
  std::chrono::milliseconds backoff{0};
};

HttpServer::HttpServer(HttpServerOptions options, const Router& router)
    : impl_(std::make_unique<Impl>(std::move(options), router)) {}

HttpServer::~HttpServer() = default;

unsigned short HttpServer::start() {
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(impl_->shared.options.address, ec);
  if (ec) throw std::runtime_error("--listen: '" + impl_->shared.options.address + "' is not an IP address");
  const tcp::endpoint endpoint(address, impl_->shared.options.port);
  auto& a = impl_->acceptor;
  a.open(endpoint.protocol(), ec);
  if (!ec) set_cloexec(a.native_handle());  // a child (salient-sim) must not hold the port
  if (!ec) a.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) a.bind(endpoint, ec);
  if (!ec) a.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    throw std::runtime_error("cannot listen on " + impl_->shared.options.address + ":" +
                             std::to_string(impl_->shared.options.port) + ": " + ec.message());
  impl_->accept();
  impl_->sweep_later();
  return a.local_endpoint().port();
}

void HttpServer::run() {
  // An exception out of a handler (Beast throws from inside its parser on some inputs) would end
  // the daemon: it is logged, and the thread goes back to serving.
  const auto serve = [this] {
    for (;;) {
      try {
        impl_->io.run();
        return;
      } catch (const std::exception& e) {
        impl_->shared.log(std::string("http internal error (a handler threw): ") + e.what());
      } catch (...) {
        impl_->shared.log("http internal error (a handler threw)");
      }
    }
  };
  std::vector<std::thread> extra;
  for (int i = 1; i < impl_->shared.options.threads; ++i) extra.emplace_back(serve);
  serve();
  for (auto& t : extra) t.join();
}

void HttpServer::stop() {
  asio::post(impl_->acceptor.get_executor(), [this] {
    boost::system::error_code ec;
    impl_->acceptor.close(ec);
    impl_->retry.cancel();
    impl_->sweeper.cancel();
  });
  std::set<std::shared_ptr<Session>> sessions;
  std::set<std::shared_ptr<WsSession>> websockets;
  {
    std::lock_guard lock(impl_->shared.mutex);
    impl_->shared.stopping = true;
    sessions = impl_->shared.sessions;
    websockets = impl_->shared.websockets;
  }
  for (const auto& s : sessions) stop_session(s);
  for (const auto& w : websockets) stop_websocket(w);
}

}  // namespace salient::server
