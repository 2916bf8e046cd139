// Fuzz target for raw HTTP requests, through the steps the server takes: Beast's parser with the
// server's limits, split_target, the router's refusal on the header, the WebSocket acceptor or
// dispatch; every JSON response (each error above all) must parse, whatever bytes it echoes.
#include <stdlib.h>

#include <algorithm>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "protocol/marlin/line_codec.hpp"
#include "server/api/api_json.hpp"
#include "server/api/routes.hpp"
#include "server/http/multipart.hpp"
#include "server/jobs/job_service.hpp"
#include "server/jobs/job_settings.hpp"
#include "server/printers/print_file.hpp"
#include "server/printers/printer.hpp"
#include "server/store/sha256.hpp"

using namespace salient::server;
namespace beast = boost::beast;
namespace http = beast::http;
using nlohmann::json;

namespace {

constexpr std::size_t kHeaderLimit = 16 * 1024;  // as http_server.cpp
constexpr std::size_t kBodyLimit = 1u << 20;

// The daemon's routes that need no printer or job queue, and stand-ins for the others that run
// the same parsers on the request (multipart, settings, JSON bodies, commands, G-code) and echo
// outside bytes (ids, file names, queries) the way the real ones do. The key is "fuzz-key".
struct Daemon {
  std::filesystem::path dir;
  Store store;
  ApiKeys keys;
  EventHub hub;
  Router router;
  WebSocketAcceptor websocket;

  static std::filesystem::path make_dir() {
    char name[] = "/tmp/http_request_fuzz.XXXXXX";
    if (!mkdtemp(name)) std::abort();
    return name;
  }
  static Store& with_key(Store& s) {
    s.db()
        .prepare("INSERT INTO api_keys (key_digest, label, created_at) VALUES (?, 'fuzz', 0)")
        .bind(1, std::string_view(sha256_hex("fuzz-key")))
        .run();
    return s;
  }

  Daemon() : dir(make_dir()), store(dir), keys(with_key(store)), websocket(events_endpoint(hub, keys)) {
    router.set_authenticator([this](const HttpRequest& r) { return keys.authenticate(r); });
    add_system_routes(router, store, NodeConfig{});
    add_event_route(router);
    router.add("POST", "/api/v1/jobs", Access::key, [](const HttpRequest& r, const PathParams&) {
      std::string filename = "model", settings;
      if (const auto boundary = multipart_boundary(r.header("content-type"))) {
        try {
          for (const FormPart& p : parse_multipart(r.body, *boundary)) {
            if (p.name == "file") filename = p.filename.value_or("model");
            if (p.name == "settings") settings = p.body;
          }
        } catch (const std::invalid_argument& e) {
          throw ApiError(400, "bad_request", e.what());
        }
      } else {
        if (auto f = r.query.find("filename"); f != r.query.end()) filename = f->second;
        if (auto s = r.query.find("settings"); s != r.query.end()) settings = s->second;
      }
      const JobSettings s = parse_job_settings(settings, 32);
      return json_response(
          201, {{"filename", sanitize_filename(filename)}, {"settings", json::parse(s.canonical)}});
    });
    router.add("GET", "/api/v1/jobs", Access::key, [](const HttpRequest& r, const PathParams&) {
      return json_response(200, {{"jobs", json::array()}, {"query", r.query}});
    });
    router.add("GET", "/api/v1/jobs/{id}", Access::key,
               [](const HttpRequest&, const PathParams& p) -> HttpResponse {
                 throw ApiError(404, "not_found", "no job " + p.at("id"));
               });
    router.add("DELETE", "/api/v1/jobs/{id}", Access::key,
               [](const HttpRequest&, const PathParams& p) -> HttpResponse {
                 throw StoreError("cannot remove " + p.at("id"), p.at("id").size() % 2 == 0);  // 507 or 500
               });
    router.add("POST", "/api/v1/printers/{id}/command", Access::key,
               [](const HttpRequest& r, const PathParams& p) {
                 const auto commands = parse_commands(parse_json_body(r, 256u << 10, 32));
                 for (const std::string& c : commands)  // each goes to the printer as one framed line
                   if (c.empty() || c.size() > salient::protocol::marlin::kMaxCommandBytes ||
                       c.find('\n') != std::string::npos)
                     std::abort();
                 return json_response(202, {{"printer", p.at("id")}, {"commands", commands}});
               });
    router.add("POST", "/api/files/local", Access::key, [](const HttpRequest& r, const PathParams&) {
      const auto boundary = multipart_boundary(r.header("content-type"));
      if (!boundary) throw ApiError(400, "bad_request", "send multipart/form-data with a 'file' part");
      std::vector<FormPart> parts;
      try {
        parts = parse_multipart(r.body, *boundary);
      } catch (const std::invalid_argument& e) {
        throw ApiError(400, "bad_request", e.what());
      }
      const auto file = std::find_if(parts.begin(), parts.end(),
                                     [](const FormPart& p) { return p.name == "file" && p.filename; });
      if (file == parts.end())
        throw ApiError(400, "bad_request", "the multipart body has no 'file' part with a filename");
      const std::string name = sanitize_filename(*file->filename);
      return json_response(201, {{"name", name}, {"commands", check_printable(name, file->body)}});
    });
    router.set_exception_mapper(
        [](const std::exception& e, const std::string&) -> std::optional<HttpResponse> {
          if (const auto* s = dynamic_cast<const StoreError*>(&e); s && s->disk_full())
            return error_response(507, "insufficient_storage", "the server's disk is full");
          return std::nullopt;
        });
  }
  ~Daemon() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

void check(const HttpResponse& r) {
  if (r.status < 100 || r.status > 599) std::abort();
  if (r.content_type.rfind("application/json", 0) != 0 || (r.body.empty() && r.status < 400)) return;
  json j;
  try {
    j = json::parse(r.body);  // throws on invalid UTF-8: json_text() must have replaced it
  } catch (const json::exception&) {
    std::abort();
  }
  if (r.status < 400) return;
  const json* e = j.is_object() && j.contains("error") ? &j["error"] : nullptr;
  if (!e || !e->is_object() || !e->contains("code") || !(*e)["code"].is_string() || !e->contains("message") ||
      !(*e)["message"].is_string())
    std::abort();
}

// One request from the front of the input, as Session::on_header and on_request take it; the bytes
// it used when the connection stays open for another, else 0.
std::size_t serve_one(Daemon& daemon, const std::uint8_t* data, std::size_t size) {
  http::request_parser<http::string_body> parser;
  parser.header_limit(kHeaderLimit);
  parser.body_limit(kBodyLimit);
  parser.eager(true);
  beast::error_code ec;
  std::size_t at = 0;
  while (!parser.is_done()) {
    const std::size_t used = parser.put(boost::asio::buffer(data + at, size - at), ec);
    at += used;
    if (ec == http::error::need_more) ec = {};
    if (ec || used == 0) break;
  }
  if (ec == http::error::header_limit)
    return check(error_response(431, "header_too_large", "the header is too large")), 0;
  if (ec == http::error::body_limit)
    return check(error_response(413, "too_large", "the body is too large")), 0;
  if (ec) return check(error_response(400, "bad_request", "malformed HTTP request: " + ec.message())), 0;
  if (!parser.is_header_done()) return 0;  // the server waits for the rest, then times out
  auto& in = parser.get();
  HttpRequest request;
  request.method = std::string(in.method_string());
  request.target = std::string(in.target());
  for (const auto& field : in) {
    std::string name(field.name_string());
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
    request.headers[name] = std::string(field.value());
  }
  request.remote = "127.0.0.1";
  if (!split_target(request.target, request.path, request.query)) return 0;  // a fixed 400, and close
  const bool upgrade = beast::websocket::is_upgrade(in);
  if (!upgrade)
    if (auto refused = daemon.router.refusal(request)) return check(*refused), 0;
  if (!parser.is_done()) return 0;
  request.body = in.body();
  if (upgrade) {
    WebSocketAccept accepted = daemon.websocket(request);
    if (!accepted.channel) return check(accepted.refusal), 0;
    while (auto m = accepted.channel->next())
      if (json::parse(*m, nullptr, false).is_discarded()) std::abort();
    accepted.channel->closed();
    return 0;
  }
  check(daemon.router.dispatch(request));
  return in.keep_alive() ? at : 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Daemon daemon;
  // Pipelined requests on one connection, as long as each response keeps it open.
  for (int n = 0; n < 8 && size > 0; ++n) {
    const std::size_t used = serve_one(daemon, data, size);
    if (used == 0) break;
    data += used, size -= used;
  }
  return 0;
}
