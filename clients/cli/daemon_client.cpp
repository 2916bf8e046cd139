#include "clients/cli/daemon_client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

namespace salient::cli {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

std::string error_message(const std::string& body, int status) {
  const auto j = nlohmann::json::parse(body, nullptr, false);
  if (j.is_object() && j.contains("error") && j["error"].is_object() && j["error"].contains("message"))
    return j["error"]["message"].get<std::string>() + " (HTTP " + std::to_string(status) + ")";
  return "HTTP " + std::to_string(status) + (body.empty() ? "" : ": " + body.substr(0, 200));
}

}  // namespace

DaemonAddress resolve_daemon(const std::string& server_option, const std::string& key_option) {
  DaemonAddress a;
  std::string server = server_option;
  if (server.empty())
    if (const char* env = std::getenv("SALIENT_SERVER")) server = env;
  if (!server.empty()) {
    std::string rest = server;
    if (rest.rfind("http://", 0) == 0)
      rest = rest.substr(7);
    else if (rest.find("://") != std::string::npos)
      throw DaemonError(0, "--server: only http:// is supported, got " + server);
    rest = rest.substr(0, rest.find('/'));
    const std::size_t colon = rest.rfind(':');
    a.host = rest.substr(0, colon);
    a.port = colon == std::string::npos ? "80" : rest.substr(colon + 1);
  }
  a.key = key_option;
  if (a.key.empty())
    if (const char* env = std::getenv("SALIENT_API_KEY")) a.key = env;
  if (a.key.empty()) {
    std::ifstream f("var/api-key");
    std::getline(f, a.key);
  }
  return a;
}

struct DaemonClient::Impl {
  DaemonAddress address;
  asio::io_context io;

  tcp::resolver::results_type resolve() {
    beast::error_code ec;
    auto r = tcp::resolver(io).resolve(address.host, address.port, ec);
    if (ec) throw DaemonError(0, "cannot resolve " + address.host + ": " + ec.message());
    return r;
  }

  DaemonReply exchange(http::request<http::string_body>& req) {
    beast::tcp_stream stream(io);
    beast::error_code ec;
    stream.connect(resolve(), ec);
    if (ec)
      throw DaemonError(0, "cannot reach salientd at " + address.host + ":" + address.port + " (" +
                               ec.message() + "): is it running? (make run)");
    req.set(http::field::host, address.host + ":" + address.port);
    req.set("X-Api-Key", address.key);
    req.prepare_payload();
    http::write(stream, req, ec);
    beast::flat_buffer buffer;
    http::response_parser<http::string_body> parser;
    parser.body_limit(1ull << 32);
    if (!ec) http::read(stream, buffer, parser, ec);
    if (ec) throw DaemonError(0, "salientd at " + address.host + ":" + address.port + ": " + ec.message());
    auto& res = parser.get();
    DaemonReply out{static_cast<int>(res.result_int()), std::move(res.body()),
                    std::string(res[http::field::content_type]), std::string(res[http::field::location]),
                    std::string(res[http::field::date])};
    stream.socket().shutdown(tcp::socket::shutdown_both, ec);
    if (out.status >= 400) throw DaemonError(out.status, error_message(out.body, out.status));
    return out;
  }
};

DaemonClient::DaemonClient(DaemonAddress address) : impl_(std::make_unique<Impl>()) {
  impl_->address = std::move(address);
}
DaemonClient::~DaemonClient() = default;

DaemonReply DaemonClient::request(const std::string& method, const std::string& target,
                                  const std::string& body, const std::string& content_type) {
  http::request<http::string_body> req(http::string_to_verb(method), target, 11);
  if (!body.empty()) {
    req.set(http::field::content_type, content_type);
    req.body() = body;
  }
  return impl_->exchange(req);
}

DaemonReply DaemonClient::upload(const std::string& target, const std::string& field,
                                 const std::string& filename, const std::string& bytes,
                                 const std::vector<std::pair<std::string, std::string>>& fields) {
  std::mt19937_64 rng{std::random_device{}()};
  const std::string boundary = "----salient" + std::to_string(rng());
  std::string body;
  for (const auto& [name, value] : fields)
    body += "--" + boundary + "\r\nContent-Disposition: form-data; name=\"" + name + "\"\r\n\r\n" + value +
            "\r\n";
  body += "--" + boundary + "\r\nContent-Disposition: form-data; name=\"" + field + "\"; filename=\"" +
          filename + "\"\r\nContent-Type: application/octet-stream\r\n\r\n";
  body += bytes;
  body += "\r\n--" + boundary + "--\r\n";
  return request("POST", target, body, "multipart/form-data; boundary=" + boundary);
}

void DaemonClient::watch(const std::vector<std::string>& topics,
                         const std::function<bool(const std::string&)>& on_message) {
  const std::string target = "/api/v1/events";
  websocket::stream<beast::tcp_stream> ws(impl_->io);
  beast::error_code ec;
  beast::get_lowest_layer(ws).connect(impl_->resolve(), ec);
  if (ec)
    throw DaemonError(0, "cannot reach salientd at " + impl_->address.host + ":" + impl_->address.port +
                             ": " + ec.message());
  const std::string key = impl_->address.key;
  ws.set_option(
      websocket::stream_base::decorator([key](websocket::request_type& r) { r.set("X-Api-Key", key); }));
  ws.handshake(impl_->address.host + ":" + impl_->address.port, target, ec);
  if (ec) {
    request("GET", target);  // a plain GET says why (401 bad key…) and throws
    throw DaemonError(0, "WebSocket handshake: " + ec.message());
  }
  // Subscribing by message (not ?topics=) makes the daemon answer "subscribed" once the
  // subscription holds: from then on no event is missed.
  ws.text(true);
  ws.write(asio::buffer(nlohmann::json{{"subscribe", topics}}.dump()), ec);
  if (ec) throw DaemonError(0, "event stream: " + ec.message());
  beast::flat_buffer buffer;
  for (;;) {
    ws.read(buffer, ec);
    if (ec == websocket::error::closed) {
      const std::string reason(ws.reason().reason.c_str());
      throw DaemonError(
          0, "salientd closed the event stream" + (reason.empty() ? std::string() : ": " + reason));
    }
    if (ec) throw DaemonError(0, "event stream: " + ec.message());
    const std::string text = beast::buffers_to_string(buffer.data());
    buffer.consume(buffer.size());
    if (!on_message(text)) break;
  }
  ws.close(websocket::close_code::normal, ec);
}

}  // namespace salient::cli
