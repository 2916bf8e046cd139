// Internal to server/http (includes Asio; never include it from outside server/http): what the
// listener, the HTTP sessions and the WebSocket sessions share — the options, the registry of
// live sessions (for a graceful stop) and the connection limits — and the calls between the
// three files. Beast stays in the .cpp files: the upgrade hands over a socket and our request.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>

#include "server/http/http_server.hpp"

namespace salient::server::http_internal {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kHeaderLimit = 16 * 1024;

using WebSocketRoute = std::pair<const std::string, WebSocketAcceptor>;  // HttpServerOptions::websockets

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
    // A trusted proxy carries every client's connections: only the overall limit applies to it.
    else if (shared.per_address[address] >= shared.options.max_connections_per_address &&
             !shared.options.trusted_proxies.trusts(address))
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

void set_cloexec(int fd);

// http_session.cpp: one HTTP connection, registered in shared.sessions until it closes.
void start_session(tcp::socket socket, Shared& shared, std::shared_ptr<ConnectionSlot> slot);
void stop_session(const std::shared_ptr<Session>& session);   // graceful: after its response
void sweep_session(const std::shared_ptr<Session>& session);  // drop it if its socket is gone

// ws_session.cpp: the connection upgraded, registered in shared.websockets until it closes
// (not registered when the server is stopping).
// `request` is the upgrade request as read (its headers answer the handshake); `subprotocol`, when
// not empty, is the Sec-WebSocket-Protocol chosen from those the client offered.
void start_websocket(tcp::socket socket, std::shared_ptr<WebSocketChannel> channel, Shared& shared,
                     std::shared_ptr<ConnectionSlot> slot, const HttpRequest& request,
                     const std::string& subprotocol);
void stop_websocket(const std::shared_ptr<WsSession>& session);

}  // namespace salient::server::http_internal
