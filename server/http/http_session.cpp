// One HTTP connection: the header is read and judged first (404, 405, 401, 503 for the body
// budget), then the body, each read with its own timeout, so an upload is cut only when it stalls.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <ctime>
#include <optional>
#include <vector>

#include "server/http/http_shared.hpp"

namespace salient::server::http_internal {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

// After a response that ends the connection, what the client still sends is read and dropped for
// a while: closing with unread bytes resets the connection, and the client may lose the response.
constexpr std::size_t kLingerBytes = 1u << 20;
constexpr std::chrono::seconds kLingerTime{2};
// What a file download holds per connection (HttpResponse::file).
constexpr std::size_t kFileChunk = 64 * 1024;

// RFC 9110 §6.6.1: a server with a clock sends Date; `salient doctor` compares it with its own.
std::string http_date_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[40];
  std::strftime(text, sizeof text, "%a, %d %b %Y %H:%M:%S GMT", &tm);
  return text;
}

void set_cloexec(int fd) {
  if (fd >= 0) ::fcntl(fd, F_SETFD, ::fcntl(fd, F_GETFD) | FD_CLOEXEC);
}

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
    forwarded(slot_->address());
    // RFC 9112 §6.3: a request whose codings do not end with chunked has no knowable length; its
    // bytes must not be read as the next request (smuggling). 400, and the connection goes.
    if (in.find(http::field::transfer_encoding) != in.end() && !parser_->chunked())
      return reply_error(400, "bad_request", "Transfer-Encoding must end with chunked");
    if (!split_target(request_.target, request_.path, request_.query))
      return respond(error_response(400, "bad_request", "malformed percent-encoding in the URL"), false);
    // An upgrade to a WebSocket's path is judged by its acceptor (its own key); anything else by
    // the router.
    acceptor_ = websocket::is_upgrade(in) ? websocket_acceptor(request_.path) : nullptr;
    if (!acceptor_)
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
    if (acceptor_) {
      route_ = "websocket " + acceptor_->first;
      WebSocketAccept accepted = acceptor_->second(request_);
      if (accepted.channel) return upgrade(std::move(accepted.channel), accepted.subprotocol);
      return respond(std::move(accepted.refusal), false);
    }
    HttpResponse response = shared_.router.dispatch(request_, &route_);
    release_body();
    respond(std::move(response), in.keep_alive());
  }

  // The acceptor for an upgrade to `path`, with its key (see HttpServerOptions::websockets);
  // null: none.
  const WebSocketRoute* websocket_acceptor(const std::string& path) const {
    const auto& all = shared_.options.websockets;
    if (const auto it = all.find(path); it != all.end()) return &*it;
    const WebSocketRoute* best = nullptr;
    for (const WebSocketRoute& route : all) {
      const std::string& key = route.first;
      if (key.size() < 2 || key.compare(key.size() - 2, 2, "/*") != 0) continue;
      const std::size_t n = key.size() - 1;  // the prefix, with its "/"
      if (path.size() > n && path.compare(0, n, key, 0, n) == 0 && (!best || n > best->first.size() - 1))
        best = &route;
    }
    return best;
  }

  // The client's address and URL: the peer's own, unless it is a trusted proxy (client_address.hpp).
  void forwarded(const std::string& peer) {
    const TrustedProxies& trusted = shared_.options.trusted_proxies;
    const bool proxy = trusted.trusts(peer);
    request_.remote = client_address(peer, request_.header("x-forwarded-for"), trusted);
    request_.base_path = base_path_of(proxy, request_.header("x-forwarded-prefix"),
                                      request_.header("x-script-name"), shared_.options.base_path);
    if (!proxy) return;
    const std::string proto = request_.header("x-forwarded-proto");
    if (proto == "https" || proto == "http") request_.scheme = proto;
    const std::string host = request_.header("x-forwarded-host");
    if (!host.empty()) request_.headers["host"] = host.substr(0, host.find(','));
  }

  std::string client() const { return request_.remote.empty() ? slot_->address() : request_.remote; }

  // Hands the connection to a WebSocket session; this HTTP session ends here.
  void upgrade(std::shared_ptr<WebSocketChannel> channel, const std::string& subprotocol) {
    upgraded_ = true;  // from here on stream_ is the WebSocket's
    {
      std::lock_guard lock(shared_.mutex);
      shared_.sessions.erase(shared_from_this());
    }
    if (shared_.options.on_response) shared_.options.on_response(method_, route_, 101, elapsed(), client());
    start_websocket(stream_.release_socket(), std::move(channel), shared_, std::move(slot_), request_,
                    subprotocol);
  }

  // A request that was answered: written, then logged and counted.
  void respond(HttpResponse response, bool keep_alive) {
    keep_alive_ = keep_alive && parser_->is_done() && !closing_;
    const bool head = parser_->is_header_done() && parser_->get().method() == http::verb::head;
    write(std::move(response), head);
    if (shared_.options.on_response)
      shared_.options.on_response(method_, route_, response_status_, elapsed(), client());
  }

  // A request that could not be read: the stream is not in a known state any more.
  void reply_error(int status, const std::string& code, const std::string& message) {
    busy_ = true;
    keep_alive_ = false;
    if (route_ == "unmatched") route_ = "invalid";
    write(error_response(status, code, message), false);
    if (shared_.options.on_response)
      shared_.options.on_response(method_, route_, status, elapsed(), client());
  }

  template <class Body>
  void set_header(http::response<Body>& out, const HttpResponse& r) {
    out.set(http::field::server, "salientd");
    out.set(http::field::date, http_date_now());
    out.set(http::field::content_type, r.content_type);
    for (const auto& [name, value] : r.headers) {
      // A path in Location is the client's: under the proxy's prefix ("/salient/api/v1/jobs/…").
      const bool path = name == "Location" && value.size() > 1 && value[0] == '/' && value[1] != '/';
      out.set(name, path ? request_.base_path + value : value);
    }
    out.keep_alive(keep_alive_);
  }

  void write(HttpResponse r, bool head) {
    if (r.file) return write_file(std::move(r), head);
    response_status_ = r.status;
    auto out = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(r.status), 11);
    set_header(*out, r);
    out->body() = std::move(r.body);
    out->prepare_payload();
    if (head) out->body().clear();
    stream_.expires_after(shared_.options.timeout);
    writing_ = true;
    http::async_write(stream_, *out, [self = shared_from_this(), out](beast::error_code ec, std::size_t) {
      self->written(ec);
    });
  }

  // A file body, a chunk at a time: each chunk is read when the last one has gone, and each
  // write has the request timeout, so a client that stops reading is cut, not buffered for.
  struct FileStream {
    explicit FileStream(int fd) : fd(fd) {}
    ~FileStream() { ::close(fd); }
    int fd;
    std::uint64_t offset = 0, left = 0;
    std::vector<char> chunk;
    http::response<http::buffer_body> response;
    std::optional<http::response_serializer<http::buffer_body>> serializer;
  };

  void write_file(HttpResponse r, bool head) {
    const int fd = ::open(r.file->path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)  // removed between the route and now (a job deleted meanwhile)
      return write(error_response(404, "not_found", "the file was removed while it was being sent"), head);
    auto s = std::make_shared<FileStream>(fd);
    s->offset = r.file->offset;
    s->left = head ? 0 : r.file->length;
    s->chunk.resize(static_cast<std::size_t>(std::min<std::uint64_t>(s->left, kFileChunk)));
    response_status_ = r.status;
    s->response.result(static_cast<http::status>(r.status));
    s->response.version(11);
    set_header(s->response, r);
    s->response.content_length(r.file->length);
    s->response.body().data = nullptr;
    s->response.body().more = s->left > 0;
    s->serializer.emplace(s->response);
    if (head) s->serializer->split(true);  // the header only: a HEAD's body is never sent
    stream_.expires_after(shared_.options.timeout);
    writing_ = true;
    http::async_write_header(stream_, *s->serializer,
                             [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                               if (ec || s->left == 0) return self->written(ec);
                               self->send_chunk(s);
                             });
  }

  void send_chunk(const std::shared_ptr<FileStream>& s) {
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(s->left, s->chunk.size()));
    const ssize_t n = ::pread(s->fd, s->chunk.data(), want, static_cast<off_t>(s->offset));
    if (n <= 0) {  // the file shrank under us: the length is promised, so the connection ends
      shared_.log("http: " + route_ + ": the file ended " + std::to_string(s->left) + " bytes early");
      return written(beast::error_code(asio::error::eof));
    }
    s->offset += static_cast<std::uint64_t>(n);
    s->left -= static_cast<std::uint64_t>(n);
    s->response.body().data = s->chunk.data();
    s->response.body().size = static_cast<std::size_t>(n);
    s->response.body().more = s->left > 0;
    stream_.expires_after(shared_.options.timeout);
    http::async_write(stream_, *s->serializer,
                      [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                        if (ec == http::error::need_buffer) ec = {};  // this chunk went: the next one
                        if (ec || s->serializer->is_done()) return self->written(ec);
                        self->send_chunk(s);
                      });
  }

  // A response has gone (or failed): the next request, or the end of the connection.
  void written(beast::error_code ec) {
    writing_ = false;
    busy_ = false;
    release_body();
    if (ec) return close();
    if (!keep_alive_ || closing_) return linger();
    read_header();
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
  const WebSocketRoute* acceptor_ = nullptr;  // the request is an upgrade to this one's path
  int response_status_ = 0;
  std::size_t reserved_ = 0, lingered_ = 0;
  Clock::time_point linger_until_{};
  std::array<char, 4096> scratch_{};
};

void start_session(tcp::socket socket, Shared& shared, std::shared_ptr<ConnectionSlot> slot) {
  auto session = std::make_shared<Session>(std::move(socket), shared, std::move(slot));
  {
    std::lock_guard lock(shared.mutex);
    shared.sessions.insert(session);
  }
  session->start();
}

void stop_session(const std::shared_ptr<Session>& session) {
  session->stop();
}
void sweep_session(const std::shared_ptr<Session>& session) {
  session->sweep();
}

}  // namespace salient::server::http_internal
