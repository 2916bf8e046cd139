// WebSocketChannel: what HttpServer needs from whoever serves a WebSocket. The server owns the
// socket and the frames; the channel owns the messages: it is told when the client connects,
// what the client says, and is asked for what to send next. No Beast type leaves the server.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "server/http/http_message.hpp"

namespace salient::server {

class WebSocketChannel {
 public:
  virtual ~WebSocketChannel() = default;
  // The handshake is done. `wake` (callable from any thread) says next() may have something.
  virtual void open(std::function<void()> wake) = 0;
  virtual void receive(const std::string& text) = 0;
  virtual std::optional<std::string> next() = 0;
  // Non-empty: close the connection with this reason (the client fell too far behind).
  virtual std::string close_reason() = 0;
  virtual void closed() = 0;  // the connection is gone
};

// Decides on an upgrade request: a channel, or the HTTP response that refuses it (401, 404…).
struct WebSocketAccept {
  std::shared_ptr<WebSocketChannel> channel;
  HttpResponse refusal;
  // The Sec-WebSocket-Protocol to answer with: one the client offered (a browser drops the
  // connection when it offered some and none is chosen); empty: none offered.
  std::string subprotocol = {};
};
using WebSocketAcceptor = std::function<WebSocketAccept(const HttpRequest&)>;

}  // namespace salient::server
