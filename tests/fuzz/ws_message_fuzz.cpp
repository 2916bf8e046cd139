// Fuzz target for WebSocket messages on /api/v1/events: each line is one client message to a
// Subscription, with events published in between. Every message the client then gets must be a
// JSON object with a type, and each message it sent gets exactly one reply until it is cut off.
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "server/common/json_text.hpp"
#include "server/events/event_hub.hpp"

using namespace salient::server;
using nlohmann::json;

namespace {

// What event_snapshots gives, echoing the topic's id as job and printer documents do.
std::vector<std::pair<std::string, std::string>> snapshot(const std::string& topic) {
  if (topic == "jobs") return {{"job", R"({"id":"a"})"}, {"job", R"({"id":"b"})"}};
  for (std::string_view prefix : {"job/", "printer/"})
    if (topic.rfind(prefix, 0) == 0)
      return {{prefix == "job/" ? "job" : "printer", json_text(json{{"id", topic.substr(prefix.size())}})}};
  return {};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  EventHubOptions limits;  // small, so that the overflow paths are reached
  limits.progress_limit = 4;
  limits.state_limit = 64;
  limits.byte_limit = 16 << 10;
  EventHub hub(limits);
  hub.set_snapshot(snapshot);
  auto s = hub.subscribe();
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  // 32 messages an input: what matters is what they hold (a 64 KB text file of lines would be
  // thousands of messages, and the fuzzer would run a few inputs a second).
  for (int n = 0; n < 32 && !rest.empty() && s->close_reason().empty(); ++n) {
    const std::size_t eol = rest.find('\n');
    const std::string message(rest.substr(0, eol));
    rest = eol == std::string_view::npos ? std::string_view{} : rest.substr(eol + 1);
    s->receive(message);
    hub.publish({"jobs", "job/a"}, "job", R"({"id":"a","progress":0.5})", Delivery::coalesce);
    hub.publish({"printers", "printer/sim"}, "printer", R"({"id":"sim"})", Delivery::always);
    hub.publish({"terminal/sim"}, "terminal", json_text(json{{"line", message.substr(0, 40)}}),
                Delivery::best_effort);
    int replies = 0;
    while (auto m = s->next()) {
      const json j = json::parse(*m, nullptr, false);
      if (!j.is_object() || !j.contains("type") || !j["type"].is_string()) std::abort();
      const std::string type = j["type"];
      replies += type == "subscribed" || type == "error";
    }
    if (s->close_reason().empty() && replies != 1) std::abort();
  }
  s->closed();
  if (hub.subscribers() != 0) std::abort();
  return 0;
}
