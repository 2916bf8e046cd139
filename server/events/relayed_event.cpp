// RelayedEvent's text in a notification; see the header.
#include "server/events/relayed_event.hpp"

#include <algorithm>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "server/common/json_text.hpp"
#include "server/jobs/job_state.hpp"

namespace salient::server {

std::string encode_event(const std::string& node, std::uint64_t seq, const std::vector<std::string>& topics,
                         const std::string& type, const std::string& data_json, Delivery delivery) {
  std::string out = json_text(
      nlohmann::json{{"n", node}, {"s", seq}, {"v", static_cast<int>(delivery)}, {"y", type}, {"t", topics}});
  out += '\n';
  out += data_json;
  return out;
}

std::string encode_interest(const std::string& node, std::uint64_t seq,
                            const std::vector<std::string>& topics) {
  return json_text(nlohmann::json{{"n", node}, {"s", seq}, {"i", topics}}) + "\n";
}

RelayMessage decode_relay_message(const std::string& text, const std::string& own_node) {
  const std::size_t line = text.find('\n');
  if (line == std::string::npos) throw std::invalid_argument("no header line");
  const auto h = nlohmann::json::parse(text.substr(0, line), nullptr, false);
  if (!h.is_object()) throw std::invalid_argument("the header is not a JSON object");
  try {
    RelayMessage out;
    if (h.contains("i")) {
      for (const auto& t : h.at("i").get<std::vector<std::string>>())
        if (EventHub::valid_topic(t)) out.interest.push_back(t);
      return out;
    }
    RelayedEvent e;
    e.node = h.at("n").get<std::string>();
    e.type = h.at("y").get<std::string>();
    // Topics this node does not know (a newer node's) are left out; the event goes to the rest.
    std::vector<std::string> topics = h.at("t").get<std::vector<std::string>>();
    std::copy_if(topics.begin(), topics.end(), std::back_inserter(e.topics), EventHub::valid_topic);
    const int v = h.at("v").get<int>();
    if (v < 0 || v > static_cast<int>(Delivery::best_effort)) throw std::invalid_argument("bad delivery");
    e.delivery = static_cast<Delivery>(v);
    if (e.topics.empty()) throw std::invalid_argument("no topic this node knows");
    e.data_json = text.substr(line + 1);
    e.local = e.node == own_node;
    out.event = std::move(e);
    return out;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("a malformed header: ") + e.what());
  }
}

std::optional<std::string> finished_job(const RelayedEvent& e) {
  if (e.type != "job" || e.topics.empty() || e.topics.back().rfind("job/", 0) != 0) return std::nullopt;
  const auto data = nlohmann::json::parse(e.data_json, nullptr, false);
  if (!data.is_object() || !data.contains("state") || !data["state"].is_string()) return std::nullopt;
  const auto state = job_state_from(data["state"].get<std::string>());
  if (!state || !finished(*state)) return std::nullopt;
  return e.topics.back().substr(4);
}

}  // namespace salient::server
