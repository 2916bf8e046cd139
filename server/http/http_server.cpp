#include "server/http/http_server.hpp"

#include <fcntl.h>

#include <algorithm>
#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/version.hpp>
#include <boost/beast/websocket.hpp>
#include <map>
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
using Clock = std::chrono::steady_clock;

constexpr std::size_t kHeaderLimit = 16 * 1024;
// After a response that ends the connection, what the client still sends is read and dropped for
// a while: closing with unread bytes resets the connection, and the client may lose the response.
constexpr std::size_t kLingerBytes = 1u << 20;
constexpr std::chrono::seconds kLingerTime{2};

class Session;
class WsSession;

struct Shared {
  Shared(const Router& r, HttpServerOptions o) : router(r), options(std::move(o)) {}
  void log(const std::string& line) const {
    if (options.log) options.log(line);
  }
  const Router& router;
  HttpServerOptions options;
  std::mutex mutex;  // sessions, websockets, stopping
  std::set<std::shared_ptr<Session>> sessions;
  std::set<std::shared_ptr<WsSession>> websockets;
  bool stopping = false;

  std::mutex limits_mutex;  // the rest: connections and bodies counted against their limits
  std::size_t connections = 0, bodies_in_flight = 0, refused_since_log = 0;
  std::map<std::string, std::size_t> per_address;
  Clock::time_point last_refusal_log = Clock::now() - std::chrono::hours(1);
};

// A connection's place within the limits, held by whichever session owns the socket.
class ConnectionSlot {
 public:
  // Null (and `why` says which limit) when the connection must be refused.
  static std::shared_ptr<ConnectionSlot> take(Shared& shared, const std::string& address, std::string& why) {
    std::lock_guard lock(shared.limits_mutex);
    if (shared.connections >= shared.options.max_connections)
      why = "the connection limit (" + std::to_string(shared.options.max_connections) +
            ", server.max_connections)";
    else if (shared.per_address[address] >= shared.options.max_connections_per_address)
      why = "the limit of " + std::to_string(shared.options.max_connections_per_address) +
            " connections from " + address + " (server.max_connections_per_address)";
    if (!why.empty()) {
      if (shared.per_address[address] == 0) shared.per_address.erase(address);
      return nullptr;
    }
    ++shared.connections, ++shared.per_address[address];
    return std::shared_ptr<ConnectionSlot>(new ConnectionSlot(shared, address));
  }
  ~ConnectionSlot() {
    std::lock_guard lock(shared_.limits_mutex);
    --shared_.connections;
    if (--shared_.per_address[address_] == 0) shared_.per_address.erase(address_);
  }
  const std::string& address() const { return address_; }

 private:
  ConnectionSlot(Shared& shared, std::string address) : shared_(shared), address_(std::move(address)) {}
  Shared& shared_;
  std::string address_;
};

void set_cloexec(int fd) {
  if (fd >= 0) ::fcntl(fd, F_SETFD, ::fcntl(fd, F_GETFD) | FD_CLOEXEC);
}

// One WebSocket connection: a read loop that hands text to the channel, and a write loop that
// drains the channel whenever it wakes us. Pings and the close handshake are Beast's.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(beast::tcp_stream stream, std::shared_ptr<WebSocketChannel> channel, Shared& shared,
            std::shared_ptr<ConnectionSlot> slot)
      : ws_(std::move(stream)), channel_(std::move(channel)), shared_(shared), slot_(std::move(slot)) {}

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
    asio::post(ws_.get_executor(), [self = shared_from_this()] {
      self->close(websocket::close_code::going_away, "server stopping");
    });
  }

 private:
  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->finish();
      try {
        self->channel_->receive(beast::buffers_to_string(self->in_.data()));
      } catch (const std::exception& e) {  // a bug, not the client's: this client goes, the server stays
        self->shared_.log(std::string("websocket internal error: ") + e.what());
        return self->close(websocket::close_code::internal_error, "internal error");
      }
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
  std::shared_ptr<ConnectionSlot> slot_;
  beast::flat_buffer in_;
  std::string out_;
  bool open_ = false, writing_ = false, closing_ = false, finished_ = false;
};

// One HTTP connection: the header is read and judged first (404, 405, 401, 503 for the body
// budget), then the body, each read with its own timeout, so an upload is cut only when it stalls.
class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket socket, Shared& shared, std::shared_ptr<ConnectionSlot> slot)
      : stream_(std::move(socket)),
        executor_(stream_.get_executor()),
        shared_(shared),
        slot_(std::move(slot)) {}
  ~Session() { release_body(); }

  void start() {
    asio::dispatch(executor_, [self = shared_from_this()] { self->read_header(); });
  }

  // Graceful stop: an idle connection closes now, a busy one after its response.
  void stop() {
    // Posted to the strand (never touching stream_ from here: an upgrade may be moving it).
    asio::post(executor_, [self = shared_from_this()] {
      if (self->upgraded_) return;
      self->closing_ = true;
      if (!self->busy_ || self->reading_body_) self->close();  // a body still arriving is not waited for
    });
  }

  // After a handler threw out of Beast (run() caught it), no operation is left to end the
  // session; its stream's timer closes the socket, and this takes it off the books.
  void sweep() {
    asio::post(executor_, [self = shared_from_this()] {
      if (!self->upgraded_ && !self->stream_.socket().is_open()) self->close();
    });
  }

 private:
  // Runs a step; an exception it lets through is a bug: a 500 for this request and a log line.
  template <class F>
  void guarded(F&& step) {
    try {
      step();
    } catch (const std::exception& e) {
      internal_error(e.what());
    } catch (...) {
      internal_error("unknown exception");
    }
  }

  void internal_error(const std::string& what) {
    shared_.log("http internal error: route=" + route_ + " " + what.substr(0, 512));
    if (writing_) return close();
    reply_error(500, "internal", "internal error (logged)");
  }

  void read_header() {
    if (closing_) return close();
    parser_.emplace();
    parser_->body_limit(shared_.options.body_limit);
    parser_->header_limit(kHeaderLimit);
    route_ = "unmatched";
    method_ = "OTHER";
    stream_.expires_after(shared_.options.timeout);
    http::async_read_header(stream_, buffer_, *parser_,
                            [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              self->guarded([&] { self->on_header(ec); });
                            });
  }

  bool read_failed(beast::error_code ec) {
    if (!ec) return false;
    // A timeout has closed the socket already (Beast's stream does): nothing can be answered.
    if (ec == http::error::end_of_stream || ec == asio::error::operation_aborted || ec == asio::error::eof ||
        ec == asio::error::connection_reset || ec == beast::error::timeout)
      close();
    else if (ec == http::error::header_limit)
      reply_error(431, "header_too_large",
                  "the request's header exceeds " + std::to_string(kHeaderLimit) + " bytes");
    else if (ec == http::error::body_limit)
      reply_error(413, "too_large",
                  "the body exceeds the limit of " + std::to_string(shared_.options.body_limit) + " bytes");
    else
      reply_error(400, "bad_request", "malformed HTTP request: " + ec.message());
    return true;
  }

  void on_header(beast::error_code ec) {
    if (read_failed(ec)) return;
    busy_ = true;
    started_ = Clock::now();
    auto& in = parser_->get();
    request_ = HttpRequest{};
    request_.method = std::string(in.method_string());
    // Metrics and logs get one label for every unknown method, whatever its bytes.
    method_ = in.method() == http::verb::unknown ? "OTHER" : request_.method;
    request_.target = std::string(in.target());
    for (const auto& field : in) {
      std::string name(field.name_string());
      std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
      request_.headers[name] = std::string(field.value());
    }
    request_.remote = slot_->address();
    // RFC 9112 §6.3: a request whose codings do not end with chunked has no knowable length; its
    // bytes must not be read as the next request (smuggling). 400, and the connection goes.
    if (in.find(http::field::transfer_encoding) != in.end() && !parser_->chunked())
      return reply_error(400, "bad_request", "Transfer-Encoding must end with chunked");
    if (!split_target(request_.target, request_.path, request_.query))
      return respond(error_response(400, "bad_request", "malformed percent-encoding in the URL"), false);
    // An upgrade is judged by the WebSocket acceptor (its own paths and key); anything else by the router.
    const bool upgrade = websocket::is_upgrade(in) && shared_.options.websocket;
    if (!upgrade)
      if (auto refused = shared_.router.refusal(request_, &route_))
        return respond(std::move(*refused), false);
    if (parser_->is_done()) return on_request();
    const auto length = parser_->content_length();
    if (!reserve_body(length ? *length : shared_.options.body_limit)) {
      HttpResponse busy =
          error_response(503, "busy", "too many request bodies are being received: try again shortly");
      busy.headers.emplace_back("Retry-After", "5");
      return respond(std::move(busy), false);
    }
    if (beast::iequals(in[http::field::expect], "100-continue")) {
      auto go_on = std::make_shared<http::response<http::empty_body>>(http::status::continue_, 11);
      stream_.expires_after(shared_.options.timeout);
      return http::async_write(stream_, *go_on,
                               [self = shared_from_this(), go_on](beast::error_code ec, std::size_t) {
                                 if (ec) return self->close();
                                 self->guarded([&] { self->read_body(); });
                               });
    }
    read_body();
  }

  void read_body() {
    reading_body_ = !parser_->is_done();
    if (!reading_body_) return on_request();
    stream_.expires_after(shared_.options.timeout);
    http::async_read_some(stream_, buffer_, *parser_,
                          [self = shared_from_this()](beast::error_code ec, std::size_t) {
                            self->guarded([&] {
                              if (!self->read_failed(ec)) self->read_body();
                            });
                          });
  }

  void on_request() {
    auto& in = parser_->get();
    request_.body = std::move(in.body());
    if (websocket::is_upgrade(in) && shared_.options.websocket) {
      route_ = "websocket";
      WebSocketAccept accepted = shared_.options.websocket(request_);
      if (accepted.channel) return upgrade(std::move(accepted.channel));
      return respond(std::move(accepted.refusal), false);
    }
    HttpResponse response = shared_.router.dispatch(request_, &route_);
    release_body();
    respond(std::move(response), in.keep_alive());
  }

  // Hands the connection to a WebSocket session; this HTTP session ends here.
  void upgrade(std::shared_ptr<WebSocketChannel> channel) {
    upgraded_ = true;  // from here on stream_ is the WebSocket's
    auto ws = std::make_shared<WsSession>(std::move(stream_), std::move(channel), shared_, std::move(slot_));
    {
      std::lock_guard lock(shared_.mutex);
      shared_.sessions.erase(shared_from_this());
      if (shared_.stopping) return;
      shared_.websockets.insert(ws);
    }
    if (shared_.options.on_response) shared_.options.on_response(method_, route_, 101, elapsed());
    ws->start(parser_->release());
  }

  // A request that was answered: written, then logged and counted.
  void respond(HttpResponse response, bool keep_alive) {
    keep_alive_ = keep_alive && parser_->is_done() && !closing_;
    const bool head = parser_->is_header_done() && parser_->get().method() == http::verb::head;
    write(std::move(response), head);
    if (shared_.options.on_response)
      shared_.options.on_response(method_, route_, response_status_, elapsed());
  }

  // A request that could not be read: the stream is not in a known state any more.
  void reply_error(int status, const std::string& code, const std::string& message) {
    busy_ = true;
    keep_alive_ = false;
    if (route_ == "unmatched") route_ = "invalid";
    write(error_response(status, code, message), false);
    if (shared_.options.on_response) shared_.options.on_response(method_, route_, status, elapsed());
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
    writing_ = true;
    http::async_write(stream_, *out, [self = shared_from_this(), out](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      self->busy_ = false;
      self->release_body();
      if (ec) return self->close();
      if (!self->keep_alive_ || self->closing_) return self->linger();
      self->read_header();
    });
  }

  // Half-closes, then drops what the client still sends until it closes too (or for a while).
  void linger() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    if (!linger_started_) linger_started_ = true, linger_until_ = Clock::now() + kLingerTime;
    if (lingered_ >= kLingerBytes || Clock::now() >= linger_until_) return close();
    stream_.expires_at(linger_until_);
    stream_.async_read_some(asio::buffer(scratch_),
                            [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                              self->lingered_ += n;
                              if (ec) return self->close();
                              self->linger();
                            });
  }

  void close() {
    release_body();
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    stream_.close();
    std::lock_guard lock(shared_.mutex);
    shared_.sessions.erase(shared_from_this());
  }

  bool reserve_body(std::size_t bytes) {
    std::lock_guard lock(shared_.limits_mutex);
    if (shared_.bodies_in_flight + bytes > shared_.options.max_bodies_in_flight) return false;
    shared_.bodies_in_flight += bytes;
    reserved_ = bytes;
    return true;
  }

  void release_body() {
    if (reserved_ == 0) return;
    std::lock_guard lock(shared_.limits_mutex);
    shared_.bodies_in_flight -= reserved_;
    reserved_ = 0;
  }

  double elapsed() const { return std::chrono::duration<double>(Clock::now() - started_).count(); }

  beast::tcp_stream stream_;
  asio::any_io_executor executor_;  // the connection's strand, kept apart from stream_
  Shared& shared_;
  std::shared_ptr<ConnectionSlot> slot_;
  // Bytes not parsed yet. Capped: Beast parses a chunked body's trailer with no header limit and
  // throws on a field over 64 KiB; a trailer that does not fit here is a 400 instead.
  beast::flat_buffer buffer_{2 * kHeaderLimit};
  std::optional<http::request_parser<http::string_body>> parser_;
  HttpRequest request_;
  std::string method_ = "OTHER", route_ = "unmatched";
  Clock::time_point started_ = Clock::now();
  bool busy_ = false, keep_alive_ = false, closing_ = false, writing_ = false, reading_body_ = false;
  bool linger_started_ = false, upgraded_ = false;
  int response_status_ = 0;
  std::size_t reserved_ = 0, lingered_ = 0;
  Clock::time_point linger_until_{};
  std::array<char, 4096> scratch_{};
};

}  // namespace

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
    sweeper.async_wait([this](beast::error_code ec) {
      if (ec) return;
      std::set<std::shared_ptr<Session>> sessions;
      {
        std::lock_guard lock(shared.mutex);
        if (shared.stopping) return;
        sessions = shared.sessions;
      }
      for (const auto& s : sessions) s->sweep();
      sweep_later();
    });
  }

  void accept() {
    acceptor.async_accept(asio::make_strand(io), [this](beast::error_code ec, tcp::socket socket) {
      on_accept(ec, std::move(socket));
    });
  }

  void on_accept(beast::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;  // closed by stop()
    {
      std::lock_guard lock(shared.mutex);
      if (shared.stopping) return;
    }
    if (ec) return accept_later(ec);
    if (backoff.count() > 0) shared.log("http accepting again");
    backoff = std::chrono::milliseconds(0);
    set_cloexec(socket.native_handle());
    beast::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);  // a small reply must not wait 40 ms for Nagle
    const std::string address = socket.remote_endpoint(ignored).address().to_string();
    std::string why;
    if (auto slot = ConnectionSlot::take(shared, address, why)) {
      auto session = std::make_shared<Session>(std::move(socket), shared, std::move(slot));
      {
        std::lock_guard lock(shared.mutex);
        shared.sessions.insert(session);
      }
      session->start();
    } else {
      refuse(std::move(socket), why);
    }
    accept();
  }

  // Out of descriptors (or memory): the pending connection stays in the backlog; try again soon
  // rather than give up accepting for good.
  void accept_later(beast::error_code ec) {
    if (backoff.count() == 0) shared.log("http accept failed (" + ec.message() + "): retrying with back-off");
    backoff = std::clamp(backoff * 2, std::chrono::milliseconds(50), std::chrono::milliseconds(1000));
    retry.expires_after(backoff);
    retry.async_wait([this](beast::error_code wait) {
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
    beast::error_code ignored;
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
  beast::error_code ec;
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
    beast::error_code ec;
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
  for (const auto& s : sessions) s->stop();
  for (const auto& w : websockets) w->stop();
}

}  // namespace salient::server
