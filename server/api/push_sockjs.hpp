// SockJsChannel: SockJS's framing over a WebSocket (sockjs-protocol 0.3, the "websocket"
// transport at /sockjs/{server}/{session}/websocket, as OctoPrint's own page and SockJS clients
// connect): "o" when open, then each batch of messages as a["…","…"] (every message a JSON string),
// "h" as a heartbeat when nothing else went out for a while; what the client sends is ["…"] (or
// one "…"), each string a message. It wraps another channel: PushChannel speaks the messages.
// Not done: the HTTP transports (xhr, xhr_streaming, eventsource, jsonp), sessions shared across
// connections, and the "c[…]" frame before a close (clients treat the WebSocket's close the same).
#pragma once

#include <chrono>
#include <memory>
#include <mutex>

#include "server/http/router.hpp"
#include "server/http/websocket_channel.hpp"

namespace salient::server {

class SockJsChannel : public WebSocketChannel {
 public:
  static constexpr std::size_t kMaxBatch = 64;  // messages in one a[…] frame
  using Clock = std::chrono::steady_clock;

  explicit SockJsChannel(std::shared_ptr<WebSocketChannel> inner,
                         std::chrono::milliseconds heartbeat = std::chrono::seconds(25));

  void open(std::function<void()> wake) override;
  void receive(const std::string& text) override;
  std::optional<std::string> next() override;
  std::string close_reason() override;
  void closed() override;
  // A heartbeat is due (nothing sent for `heartbeat`): the owner's timer wakes the socket.
  bool heartbeat_due() const;

 private:
  std::shared_ptr<WebSocketChannel> inner_;
  std::chrono::milliseconds heartbeat_;
  mutable std::mutex mutex_;
  bool opened_ = false;
  Clock::time_point last_sent_ = Clock::now();
};

// Whether `path` is /sockjs/{server}/{session}/websocket with ids SockJS allows (no dots, no
// slashes, not empty).
bool is_sockjs_websocket_path(const std::string& path);

// GET /sockjs/info (open, as SockJS clients ask before they connect): {websocket, origins,
// cookie_needed, entropy}.
void add_sockjs_routes(Router& router);

}  // namespace salient::server
