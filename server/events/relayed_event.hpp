// RelayedEvent: an event as it travels between nodes (EventRelay), and its text in a
// notification: one line of JSON (node, sequence, delivery, type, topics), a newline, then the
// event's data JSON byte for byte as published, so that subscribers get the same text on every
// node. A line with "i" (and nothing after it) is no event but "node N has subscribers to these
// topics".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "server/events/event_hub.hpp"

namespace salient::server {

struct RelayedEvent {
  std::vector<std::string> topics;
  std::string type, data_json, node;
  Delivery delivery = Delivery::always;
  bool local = false;  // published on this node
};

// `seq` keeps two equal events apart: PostgreSQL folds identical notifications of one transaction.
std::string encode_event(const std::string& node, std::uint64_t seq, const std::vector<std::string>& topics,
                         const std::string& type, const std::string& data_json, Delivery delivery);
std::string encode_interest(const std::string& node, std::uint64_t seq,
                            const std::vector<std::string>& topics);

// One or the other, from a notification's text. Throws std::invalid_argument on anything else:
// anyone may NOTIFY the channel.
struct RelayMessage {
  std::optional<RelayedEvent> event;
  std::vector<std::string> interest;  // valid topics only
};
RelayMessage decode_relay_message(const std::string& text, const std::string& own_node);

// The id of the job a "job" event says is finished (done, failed, cancelled), if it is one.
std::optional<std::string> finished_job(const RelayedEvent& e);

}  // namespace salient::server
