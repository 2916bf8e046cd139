// One WebSocket connection: a read loop that hands text to the channel, and a write loop that
// drains the channel whenever it wakes us. Pings and the close handshake are Beast's.
#include <boost/asio/post.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/empty_body.hpp>
#include <boost/beast/websocket.hpp>

#include "server/http/http_shared.hpp"

namespace salient::server::http_internal {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(beast::tcp_stream stream, std::shared_ptr<WebSocketChannel> channel, Shared& shared,
            std::shared_ptr<ConnectionSlot> slot)
      : ws_(std::move(stream)), channel_(std::move(channel)), shared_(shared), slot_(std::move(slot)) {}

  void start(http::request<http::empty_body> request, const std::string& subprotocol) {
    beast::get_lowest_layer(ws_).expires_never();
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([subprotocol](websocket::response_type& r) {
      r.set(http::field::server, "salientd");
      if (!subprotocol.empty()) r.set(http::field::sec_websocket_protocol, subprotocol);
    }));
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
      // A client that does not answer the close (or keeps its end of the TCP connection open)
      // must not hold the daemon's stop for the suggested 30 s.
      websocket::stream_base::timeout t =
          websocket::stream_base::timeout::suggested(beast::role_type::server);
      t.handshake_timeout = std::chrono::seconds(2);
      self->ws_.set_option(t);
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

void start_websocket(tcp::socket socket, std::shared_ptr<WebSocketChannel> channel, Shared& shared,
                     std::shared_ptr<ConnectionSlot> slot, const HttpRequest& request,
                     const std::string& subprotocol) {
  // The handshake needs only the request's header (Upgrade, Sec-WebSocket-Key and -Version).
  http::request<http::empty_body> header{http::verb::get, request.target, 11};
  for (const auto& [name, value] : request.headers) header.set(name, value);
  auto ws = std::make_shared<WsSession>(beast::tcp_stream(std::move(socket)), std::move(channel), shared,
                                        std::move(slot));
  {
    std::lock_guard lock(shared.mutex);
    if (shared.stopping) return;
    shared.websockets.insert(ws);
  }
  ws->start(std::move(header), subprotocol);
}

void stop_websocket(const std::shared_ptr<WsSession>& session) {
  session->stop();
}

}  // namespace salient::server::http_internal
