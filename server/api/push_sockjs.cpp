#include "server/api/push_sockjs.hpp"

#include <nlohmann/json.hpp>
#include <random>

#include "server/api/api_json.hpp"
#include "server/common/json_text.hpp"

namespace salient::server {

using nlohmann::json;

SockJsChannel::SockJsChannel(std::shared_ptr<WebSocketChannel> inner, std::chrono::milliseconds heartbeat)
    : inner_(std::move(inner)), heartbeat_(heartbeat) {}

void SockJsChannel::open(std::function<void()> wake) {
  inner_->open(std::move(wake));
}

void SockJsChannel::receive(const std::string& text) {
  json frame;
  try {
    frame = parse_json_text(text, 2);
  } catch (const std::invalid_argument&) {
    return;  // not a SockJS frame: ignored, as the push socket ignores what it cannot read
  }
  if (frame.is_string()) return inner_->receive(frame.get<std::string>());
  if (!frame.is_array()) return;
  for (const auto& message : frame)
    if (message.is_string()) inner_->receive(message.get<std::string>());
}

std::optional<std::string> SockJsChannel::next() {
  std::lock_guard lock(mutex_);
  if (!opened_) {
    opened_ = true;
    last_sent_ = Clock::now();
    return std::string("o");
  }
  json batch = json::array();
  while (batch.size() < kMaxBatch) {
    std::optional<std::string> message = inner_->next();
    if (!message) break;
    batch.push_back(std::move(*message));
  }
  if (!batch.empty()) {
    last_sent_ = Clock::now();
    return "a" + json_text(batch);
  }
  if (Clock::now() - last_sent_ >= heartbeat_) {
    last_sent_ = Clock::now();
    return std::string("h");
  }
  return std::nullopt;
}

bool SockJsChannel::heartbeat_due() const {
  std::lock_guard lock(mutex_);
  return opened_ && Clock::now() - last_sent_ >= heartbeat_;
}

std::string SockJsChannel::close_reason() {
  return inner_->close_reason();
}

void SockJsChannel::closed() {
  inner_->closed();
}

bool is_sockjs_websocket_path(const std::string& path) {
  static const std::string prefix = "/sockjs/", suffix = "/websocket";
  if (path.size() <= prefix.size() + suffix.size() || path.compare(0, prefix.size(), prefix) != 0 ||
      path.compare(path.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const std::string ids = path.substr(prefix.size(), path.size() - prefix.size() - suffix.size());
  const std::size_t slash = ids.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == ids.size()) return false;
  return ids.find('/', slash + 1) == std::string::npos && ids.find('.') == std::string::npos &&
         ids.size() <= 128;
}

void add_sockjs_routes(Router& router) {
  router.add("GET", "/sockjs/info", Access::open, [](const HttpRequest&, const PathParams&) {
    static thread_local std::mt19937 random{std::random_device{}()};  // a cache-buster, no secret
    HttpResponse r = json_response(200, {{"websocket", true},
                                         {"origins", {"*:*"}},
                                         {"cookie_needed", false},
                                         {"entropy", random() & 0x7fffffff}});
    r.headers.emplace_back("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0");
    return r;
  });
}

}  // namespace salient::server
