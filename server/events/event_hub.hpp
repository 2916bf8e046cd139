// EventHub: publish/subscribe for the WebSocket /api/v1/events. Each event goes to the topics it
// concerns ("jobs" and "job/ID", "printers" and "printer/ID", "terminal/ID"); each subscriber has
// a bounded queue. Progress events are coalesced (a newer one replaces an undelivered older one
// with the same key) or dropped when the queue is full; state changes are never dropped: a client
// that lets too many pile up is disconnected with a reason instead of silently missing one.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "server/http/websocket_channel.hpp"

namespace salient::server {

struct EventHubOptions {
  std::size_t progress_limit = 256;   // queued events beyond which progress is dropped
  std::size_t state_limit = 4096;     // queued state changes beyond which the client is cut off
  std::size_t byte_limit = 8u << 20;  // queued bytes of any kind: the same, counting replies and snapshots
};

// How an event may be treated when a client falls behind.
enum class Delivery {
  always,       // a state change: never dropped
  coalesce,     // progress: replaces an undelivered one about the same subject; dropped when full
  best_effort,  // a terminal line: dropped when the queue is full
};

// Where published events go instead of straight to the subscribers (EventRelay, between nodes):
// it delivers them back through EventHub::deliver.
using ForwardFn = std::function<void(const std::vector<std::string>& topics, const std::string& type,
                                     const std::string& data_json, Delivery delivery)>;

// A topic's current state, sent first to whoever subscribes to it: (type, data JSON) pairs.
using SnapshotFn = std::function<std::vector<std::pair<std::string, std::string>>(const std::string& topic)>;

class EventHub;

class Subscription : public WebSocketChannel {
 public:
  static constexpr std::size_t kMaxTopics = 256;  // per client

  Subscription(EventHub& hub, std::function<void()> wake);

  // Client messages: {"subscribe": [topics]}, {"unsubscribe": [topics]}; answered with
  // {"type": "subscribed", "data": {"topics": [...]}} or {"type": "error", …}.
  void receive(const std::string& text) override;
  bool subscribe(const std::string& topic);  // false: not a topic
  void unsubscribe(const std::string& topic);
  void resync(const std::string& reason);

  void open(std::function<void()> wake) override;
  std::optional<std::string> next() override;
  std::string close_reason() override;
  void closed() override;

  std::size_t pending() const;
  std::size_t dropped() const;

 private:
  friend class EventHub;
  struct Entry {
    std::string text, subject;  // subject: the topic it is about ("job/ID"), for coalescing
    Delivery delivery = Delivery::always;
  };
  // Queues an event, `texts[i]` being its message under `topics[i]`; returns the wake function
  // to call (empty: no need).
  std::function<void()> offer(const std::vector<std::string>& topics, const std::vector<std::string>& texts,
                              Delivery delivery);
  void push_reply(std::string text);
  // Queues a message that must not be dropped (a state change, a snapshot, a reply); past the
  // state limit the client is cut off instead. False then. Under mutex_.
  bool enqueue_state(std::string text, const std::string& subject);

  EventHub& hub_;
  mutable std::mutex mutex_;
  std::function<void()> wake_;
  std::set<std::string> topics_;
  std::vector<Entry> queue_;  // front = oldest; small, so a vector with an index
  std::size_t head_ = 0, states_ = 0, dropped_ = 0, bytes_ = 0;
  std::string overflow_;
  bool closed_ = false;
};

class EventHub {
 public:
  explicit EventHub(EventHubOptions options = {}) : options_(options) {}

  void set_snapshot(SnapshotFn snapshot) { snapshot_ = std::move(snapshot); }
  std::shared_ptr<Subscription> subscribe(std::function<void()> wake = {});

  // Set once before publishing starts: then publish() hands every event to `forward` (which
  // delivers it, on this node and the others, through deliver()).
  void set_forward(ForwardFn forward) { forward_ = std::move(forward); }
  // Also set once, by the relay: `subscribed` hears of each topic a subscriber takes (so that
  // other nodes learn who listens), and `remote` says whether another node has a subscriber to a
  // topic (has_subscribers counts it: a printer here then sends its terminal lines).
  void set_interest(std::function<void(const std::string& topic)> subscribed,
                    std::function<bool(const std::string& topic)> remote) {
    subscribed_ = std::move(subscribed);
    remote_interest_ = std::move(remote);
  }
  // Every topic some subscriber here has.
  std::set<std::string> topics() const;

  // `topics`: every topic the event belongs to; the last one is its subject. A subscriber to
  // several gets it once, under the subject if it asked for it, else under the first it asked for
  // (a "jobs" subscriber sees topic "jobs", not "job/ID").
  void publish(const std::vector<std::string>& topics, const std::string& type, const std::string& data_json,
               Delivery delivery = Delivery::always);
  // To this node's subscribers, now: what publish() does without a forward.
  void deliver(const std::vector<std::string>& topics, const std::string& type, const std::string& data_json,
               Delivery delivery = Delivery::always);
  // After events may have been missed (the relay lost its connection): every subscriber gets
  // {"type": "resync", "data": {"reason": …}} and then each of its topics' snapshots again, as on
  // subscribing, so that it holds the current state whatever it missed.
  void resync(const std::string& reason);
  bool has_subscribers(const std::string& topic) const;  // here or, with a relay, on another node
  std::size_t subscribers() const;

  static bool valid_topic(const std::string& topic);
  // {"type", "topic", "time", "data"}; an empty `topic` is null (a reply about the connection).
  static std::string message(const std::string& topic, const std::string& type, const std::string& data_json);

 private:
  static double now_seconds();  // to the millisecond, as messages' "time"
  static std::string message_at(const std::string& topic, const std::string& type,
                                const std::string& data_json, double time);
  friend class Subscription;
  void remove(const Subscription* s);

  EventHubOptions options_;
  SnapshotFn snapshot_;
  ForwardFn forward_;
  std::function<void(const std::string&)> subscribed_;
  std::function<bool(const std::string&)> remote_interest_;
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<Subscription>> subscribers_;
};

}  // namespace salient::server
