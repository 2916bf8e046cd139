#include "server/http/http_server.hpp"

#include <algorithm>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/version.hpp>
#include <boost/beast/websocket.hpp>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <vector>

namespace salient::server {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

class Session;
class WsSession;

struct Shared {
  Shared(const Router& r, HttpServerOptions o) : router(r), options(std::move(o)) {}
  const Router& router;
  HttpServerOptions options;
  std::mutex mutex;
  std::set<std::shared_ptr<Session>> sessions;
  std::set<std::shared_ptr<WsSession>> websockets;
  bool stopping = false;
};

// One WebSocket connection: a read loop that hands text to the channel, and a write loop that
// drains the channel whenever it wakes us. Pings and the close handshake are Beast's.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(beast::tcp_stream stream, std::shared_ptr<WebSocketChannel> channel, Shared& shared)
      : ws_(std::move(stream)), channel_(std::move(channel)), shared_(shared) {}

  void start(http::request<http::string_body> request) {
    beast::get_lowest_layer(ws_).expires_never();
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& r) { r.set(http::field::server, "salientd"); }));
    ws_.read_message_max(64 * 1024);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->finish();
      self->open_ = true;
      std::weak_ptr<WsSession> weak = self;
      self->channel_->open([weak] {
        if (auto s = weak.lock()) asio::post(s->ws_.get_executor(), [s] { s->pump(); });
      });
      self->read();
      self->pump();
    });
  }

  void stop() {
    asio::post(ws_.get_executor(), [self = shared_from_this()] { self->close(websocket::close_code::going_away, "server stopping"); });
  }

 private:
  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->finish();
      self->channel_->receive(beast::buffers_to_string(self->in_.data()));
      self->in_.consume(self->in_.size());
      self->read();
    });
  }

  void pump() {
    if (writing_ || !open_ || closing_) return;
    if (std::string reason = channel_->close_reason(); !reason.empty())
      return close(websocket::close_code::policy_error, reason);
    auto text = channel_->next();
    if (!text) return;
    writing_ = true;
    out_ = std::move(*text);
    ws_.text(true);
    ws_.async_write(asio::buffer(out_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      if (ec) return self->finish();
      self->pump();
    });
  }

  void close(websocket::close_code code, const std::string& reason) {
    if (closing_ || !open_) return finish();
    closing_ = true;
    websocket::close_reason r(code);
    r.reason = reason.substr(0, 120);  // a control frame holds 125 bytes
    ws_.async_close(r, [self = shared_from_this()](beast::error_code) { self->finish(); });
  }

  void finish() {
    if (finished_) return;
    finished_ = true;
    channel_->closed();
    std::lock_guard lock(shared_.mutex);
    shared_.websockets.erase(shared_from_this());
  }

  websocket::stream<beast::tcp_stream> ws_;
  std::shared_ptr<WebSocketChannel> channel_;
  Shared& shared_;
  beast::flat_buffer in_;
  std::string out_;
  bool open_ = false, writing_ = false, closing_ = false, finished_ = false;
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket socket, Shared& shared) : stream_(std::move(socket)), shared_(shared) {}

  void start() { asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); }); }

  // Graceful stop: an idle connection closes now, a busy one after its response.
  void stop() {
    asio::post(stream_.get_executor(), [self = shared_from_this()] {
      self->closing_ = true;
      if (!self->busy_) self->close();
    });
  }

 private:
  void read() {
    if (closing_) return close();
    parser_.emplace();
    parser_->body_limit(shared_.options.body_limit);
    parser_->header_limit(16 * 1024);
    stream_.expires_after(shared_.options.timeout);
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

  void on_read(beast::error_code ec) {
    if (ec == http::error::end_of_stream || ec == beast::error::timeout || ec == asio::error::operation_aborted) return close();
    if (ec == http::error::body_limit) return reply_error(413, "too_large", "the body exceeds the limit of " +
                                                                   std::to_string(shared_.options.body_limit) + " bytes");
    if (ec) return reply_error(400, "bad_request", "malformed HTTP request: " + ec.message());
    busy_ = true;
    const auto started = std::chrono::steady_clock::now();
    auto& in = parser_->get();
    HttpRequest request;
    request.method = std::string(in.method_string());
    request.target = std::string(in.target());
    for (const auto& field : in) {
      std::string name(field.name_string());
      std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
      request.headers[name] = std::string(field.value());
    }
    request.body = std::move(in.body());
    beast::error_code ignored;
    request.remote = stream_.socket().remote_endpoint(ignored).address().to_string();
    std::string route = "unmatched";
    if (websocket::is_upgrade(in) && shared_.options.websocket && split_target(request.target, request.path, request.query)) {
      WebSocketAccept accepted = shared_.options.websocket(request);
      if (accepted.channel) return upgrade(std::move(accepted.channel));
      keep_alive_ = false;
      write(std::move(accepted.refusal), false);
      if (shared_.options.on_response) shared_.options.on_response(request.method, "websocket", response_status_, 0);
      return;
    }
    HttpResponse response = split_target(request.target, request.path, request.query)
                                ? shared_.router.dispatch(request, &route)
                                : error_response(400, "bad_request", "malformed percent-encoding in the URL");
    keep_alive_ = in.keep_alive() && !closing_;
    const bool head = in.method() == http::verb::head;
    write(std::move(response), head);
    if (shared_.options.on_response)
      shared_.options.on_response(request.method, route, response_status_,
                                  std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  }

  // Hands the connection to a WebSocket session; this HTTP session ends here.
  void upgrade(std::shared_ptr<WebSocketChannel> channel) {
    auto ws = std::make_shared<WsSession>(std::move(stream_), std::move(channel), shared_);
    {
      std::lock_guard lock(shared_.mutex);
      shared_.sessions.erase(shared_from_this());
      if (shared_.stopping) return;
      shared_.websockets.insert(ws);
    }
    ws->start(parser_->release());
  }

  void reply_error(int status, const std::string& code, const std::string& message) {
    busy_ = true;
    keep_alive_ = false;  // the stream is not in a known state any more
    write(error_response(status, code, message), false);
  }

  void write(HttpResponse r, bool head) {
    response_status_ = r.status;
    auto out = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(r.status), 11);
    out->set(http::field::server, "salientd");
    out->set(http::field::content_type, r.content_type);
    for (const auto& [name, value] : r.headers) out->set(name, value);
    out->keep_alive(keep_alive_);
    out->body() = std::move(r.body);
    out->prepare_payload();
    if (head) out->body().clear();
    stream_.expires_after(shared_.options.timeout);
    http::async_write(stream_, *out, [self = shared_from_this(), out](beast::error_code ec, std::size_t) {
      self->busy_ = false;
      if (ec || !self->keep_alive_ || self->closing_) return self->close();
      self->read();
    });
  }

  void close() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
    stream_.close();
    std::lock_guard lock(shared_.mutex);
    shared_.sessions.erase(shared_from_this());
  }

  beast::tcp_stream stream_;
  Shared& shared_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  bool busy_ = false, keep_alive_ = false, closing_ = false;
  int response_status_ = 0;
};

}  // namespace

struct HttpServer::Impl {
  Impl(HttpServerOptions options, const Router& router)
      : shared{router, std::move(options)}, io(std::max(1, shared.options.threads)), acceptor(asio::make_strand(io)) {}

  void accept() {
    acceptor.async_accept(asio::make_strand(io), [this](beast::error_code ec, tcp::socket socket) {
      if (ec) return;  // closed by stop()
      auto session = std::make_shared<Session>(std::move(socket), shared);
      {
        std::lock_guard lock(shared.mutex);
        if (shared.stopping) return;
        shared.sessions.insert(session);
      }
      session->start();
      accept();
    });
  }

  Shared shared;
  asio::io_context io;
  tcp::acceptor acceptor;
};

HttpServer::HttpServer(HttpServerOptions options, const Router& router)
    : impl_(std::make_unique<Impl>(std::move(options), router)) {}

HttpServer::~HttpServer() = default;

unsigned short HttpServer::start() {
  beast::error_code ec;
  const auto address = asio::ip::make_address(impl_->shared.options.address, ec);
  if (ec) throw std::runtime_error("--listen: '" + impl_->shared.options.address + "' is not an IP address");
  const tcp::endpoint endpoint(address, impl_->shared.options.port);
  auto& a = impl_->acceptor;
  a.open(endpoint.protocol(), ec);
  if (!ec) a.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) a.bind(endpoint, ec);
  if (!ec) a.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    throw std::runtime_error("cannot listen on " + impl_->shared.options.address + ":" +
                             std::to_string(impl_->shared.options.port) + ": " + ec.message());
  impl_->accept();
  return a.local_endpoint().port();
}

void HttpServer::run() {
  std::vector<std::thread> extra;
  for (int i = 1; i < impl_->shared.options.threads; ++i) extra.emplace_back([this] { impl_->io.run(); });
  impl_->io.run();
  for (auto& t : extra) t.join();
}

void HttpServer::stop() {
  asio::post(impl_->acceptor.get_executor(), [this] {
    beast::error_code ec;
    impl_->acceptor.close(ec);
  });
  std::set<std::shared_ptr<Session>> sessions;
  std::set<std::shared_ptr<WsSession>> websockets;
  {
    std::lock_guard lock(impl_->shared.mutex);
    impl_->shared.stopping = true;
    sessions = impl_->shared.sessions;
    websockets = impl_->shared.websockets;
  }
  for (const auto& s : sessions) s->stop();
  for (const auto& w : websockets) w->stop();
}

}  // namespace salient::server
