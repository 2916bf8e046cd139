#include "server/events/event_hub.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "server/common/json_text.hpp"

namespace salient::server {
namespace {

bool valid_id(std::string_view id) {
  return !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '_' || c == '.';
  });
}

std::string error_reply(const std::string& message) {
  return EventHub::message("", "error", json_text(nlohmann::json{{"message", message}}));
}

}  // namespace

bool EventHub::valid_topic(const std::string& topic) {
  if (topic == "jobs" || topic == "printers" || topic == "files") return true;
  for (std::string_view prefix : {"job/", "printer/", "terminal/"})
    if (topic.rfind(prefix, 0) == 0) return valid_id(std::string_view(topic).substr(prefix.size()));
  return false;
}

std::string EventHub::message(const std::string& topic, const std::string& type,
                              const std::string& data_json) {
  return message_at(topic, type, data_json, now_seconds());
}

double EventHub::now_seconds() {
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  return std::round(now * 1000) / 1000;
}

std::string EventHub::message_at(const std::string& topic, const std::string& type,
                                 const std::string& data_json, double time) {
  std::string out = "{\"type\":";
  out += json_text(nlohmann::json(type));
  // Every message has the same four fields: a reply about the connection has a null topic.
  out += ",\"topic\":";
  out += topic.empty() ? "null" : json_text(nlohmann::json(topic));
  out += ",\"time\":";
  out += json_text(nlohmann::json(time));
  out += ",\"data\":";
  out += data_json.empty() ? "null" : data_json;
  out += '}';
  return out;
}

std::shared_ptr<Subscription> EventHub::subscribe(std::function<void()> wake) {
  auto s = std::make_shared<Subscription>(*this, std::move(wake));
  std::lock_guard lock(mutex_);
  subscribers_.push_back(s);
  return s;
}

void EventHub::publish(const std::vector<std::string>& topics, const std::string& type,
                       const std::string& data_json, Delivery delivery) {
  if (forward_) return forward_(topics, type, data_json, delivery);
  deliver(topics, type, data_json, delivery);
}

void EventHub::deliver(const std::vector<std::string>& topics, const std::string& type,
                       const std::string& data_json, Delivery delivery) {
  std::vector<std::shared_ptr<Subscription>> targets;
  {
    std::lock_guard lock(mutex_);
    targets = subscribers_;
  }
  if (targets.empty() || topics.empty()) return;
  // One text per topic: each subscriber gets the event under a topic it asked for.
  const double at = now_seconds();
  std::vector<std::string> texts;
  texts.reserve(topics.size());
  for (const std::string& topic : topics) texts.push_back(message_at(topic, type, data_json, at));
  for (const auto& s : targets)
    if (auto wake = s->offer(topics, texts, delivery)) wake();
}

void EventHub::resync(const std::string& reason) {
  std::vector<std::shared_ptr<Subscription>> targets;
  {
    std::lock_guard lock(mutex_);
    targets = subscribers_;
  }
  for (const auto& s : targets) s->resync(reason);
}

bool EventHub::has_subscribers(const std::string& topic) const {
  {
    std::lock_guard lock(mutex_);
    if (std::any_of(subscribers_.begin(), subscribers_.end(), [&](const auto& s) {
          std::lock_guard inner(s->mutex_);
          return s->topics_.count(topic) > 0;
        }))
      return true;
  }
  return remote_interest_ && remote_interest_(topic);
}

std::set<std::string> EventHub::topics() const {
  std::set<std::string> out;
  std::lock_guard lock(mutex_);
  for (const auto& s : subscribers_) {
    std::lock_guard inner(s->mutex_);
    out.insert(s->topics_.begin(), s->topics_.end());
  }
  return out;
}

std::size_t EventHub::subscribers() const {
  std::lock_guard lock(mutex_);
  return subscribers_.size();
}

void EventHub::remove(const Subscription* s) {
  std::lock_guard lock(mutex_);
  std::erase_if(subscribers_, [s](const auto& p) { return p.get() == s; });
}

Subscription::Subscription(EventHub& hub, std::function<void()> wake) : hub_(hub), wake_(std::move(wake)) {}

void Subscription::open(std::function<void()> wake) {
  bool any;
  {
    std::lock_guard lock(mutex_);
    wake_ = wake;
    any = head_ < queue_.size() || !overflow_.empty();
  }
  if (any && wake) wake();
}

bool Subscription::subscribe(const std::string& topic) {
  if (!EventHub::valid_topic(topic)) return false;
  {
    std::lock_guard lock(mutex_);
    if (topics_.count(topic)) return true;  // subscribed already: no second snapshot
    if (topics_.size() >= kMaxTopics) return false;
  }
  std::vector<std::pair<std::string, std::string>> snapshot;
  if (hub_.snapshot_) snapshot = hub_.snapshot_(topic);
  std::function<void()> wake;
  {
    std::lock_guard lock(mutex_);
    topics_.insert(topic);
    for (const auto& [type, data] : snapshot)
      if (!enqueue_state(EventHub::message(topic, type, data), topic)) break;
    wake = wake_;
  }
  if (wake) wake();
  if (hub_.subscribed_) hub_.subscribed_(topic);
  return true;
}

bool Subscription::enqueue_state(std::string text, const std::string& subject) {
  if (!overflow_.empty()) return false;
  if (++states_ > hub_.options_.state_limit || bytes_ + text.size() > hub_.options_.byte_limit) {
    overflow_ = "too slow: more than " + std::to_string(hub_.options_.state_limit) + " events or " +
                std::to_string(hub_.options_.byte_limit >> 20) + " MiB waiting";
    queue_.clear(), head_ = 0, states_ = 0, bytes_ = 0;
    return false;
  }
  bytes_ += text.size();
  queue_.push_back({std::move(text), subject, Delivery::always});
  return true;
}

void Subscription::resync(const std::string& reason) {
  std::set<std::string> topics;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    topics = topics_;
  }
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::string>>>> snapshots;
  for (const std::string& topic : topics)
    snapshots.emplace_back(
        topic, hub_.snapshot_ ? hub_.snapshot_(topic) : decltype(snapshots)::value_type::second_type{});
  std::function<void()> wake;
  {
    std::lock_guard lock(mutex_);
    if (enqueue_state(EventHub::message("", "resync", json_text(nlohmann::json{{"reason", reason}})), {}))
      for (const auto& [topic, snapshot] : snapshots)
        for (const auto& [type, data] : snapshot)
          if (!enqueue_state(EventHub::message(topic, type, data), topic)) break;
    wake = wake_;
  }
  if (wake) wake();
}

void Subscription::unsubscribe(const std::string& topic) {
  std::lock_guard lock(mutex_);
  topics_.erase(topic);
}

void Subscription::push_reply(std::string text) {
  std::function<void()> wake;
  {
    std::lock_guard lock(mutex_);
    enqueue_state(std::move(text), {});  // a reply counts against the bound like any state change
    wake = wake_;
  }
  if (wake) wake();
}

void Subscription::receive(const std::string& text) {
  nlohmann::json j;
  try {
    j = parse_json_text(text, 4);  // {"subscribe": ["jobs"]} is two deep
  } catch (const std::invalid_argument& e) {
    return push_reply(error_reply(std::string("the message is ") + e.what()));
  }
  if (!j.is_object())
    return push_reply(error_reply("expected a JSON object like {\"subscribe\": [\"jobs\"]}"));
  for (const auto& [key, value] : j.items()) {
    if (key != "subscribe" && key != "unsubscribe")
      return push_reply(
          error_reply("unknown field '" + key.substr(0, 64) + "': use subscribe or unsubscribe"));
    if (!value.is_array() ||
        !std::all_of(value.begin(), value.end(), [](const auto& t) { return t.is_string(); }))
      return push_reply(error_reply("'" + key + "' must be an array of topic names"));
    // The same topic twice is one topic: folded here, so that no list repeats its snapshot.
    std::set<std::string> asked;
    for (const auto& t : value) asked.insert(t.get<std::string>());
    for (const std::string& topic : asked) {
      if (key == "unsubscribe") {
        unsubscribe(topic);
      } else if (!subscribe(topic)) {
        return push_reply(error_reply("unknown topic '" + topic.substr(0, 80) +
                                      "': use jobs, job/ID, printers, printer/ID or terminal/ID, at most " +
                                      std::to_string(kMaxTopics) + " at once"));
      }
    }
  }
  nlohmann::json topics = nlohmann::json::array();
  {
    std::lock_guard lock(mutex_);
    for (const auto& t : topics_) topics.push_back(t);
  }
  push_reply(EventHub::message("", "subscribed", json_text(nlohmann::json{{"topics", topics}})));
}

std::function<void()> Subscription::offer(const std::vector<std::string>& topics,
                                          const std::vector<std::string>& texts, Delivery delivery) {
  std::lock_guard lock(mutex_);
  if (closed_ || !overflow_.empty() || topics.empty()) return {};
  // Under the subject if this client asked for it, else under the first topic it asked for.
  const std::string& subject = topics.back();
  std::size_t label = topics.size() - 1;
  if (!topics_.count(subject)) {
    label =
        static_cast<std::size_t>(std::find_if(topics.begin(), topics.end(),
                                              [&](const std::string& t) { return topics_.count(t) > 0; }) -
                                 topics.begin());
    if (label == topics.size()) return {};
  }
  const std::string& text = texts[label];
  const bool was_empty = head_ == queue_.size();
  if (delivery != Delivery::always) {
    // The newest undelivered event about the same subject: a progress update is replaced by this
    // one; a state change is kept, and this one goes after it, so that order is never lost.
    for (std::size_t i = queue_.size(); delivery == Delivery::coalesce && i-- > head_;) {
      if (queue_[i].subject != subject) continue;
      if (queue_[i].delivery != Delivery::coalesce) break;
      bytes_ += text.size() - queue_[i].text.size();
      queue_[i].text = text;
      return {};
    }
    if (queue_.size() - head_ >= hub_.options_.progress_limit ||
        bytes_ + text.size() > hub_.options_.byte_limit) {
      ++dropped_;
      return {};
    }
    bytes_ += text.size();
    queue_.push_back({text, subject, delivery});
  } else if (!enqueue_state(text, subject)) {
    return wake_;
  }
  return was_empty ? wake_ : std::function<void()>{};
}

std::optional<std::string> Subscription::next() {
  std::lock_guard lock(mutex_);
  if (head_ == queue_.size()) return std::nullopt;
  Entry e = std::move(queue_[head_++]);
  if (e.delivery == Delivery::always) --states_;
  bytes_ -= e.text.size();
  if (head_ == queue_.size() || head_ > 1024) {
    queue_.erase(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(head_));
    head_ = 0;
  }
  return std::move(e.text);
}

std::string Subscription::close_reason() {
  std::lock_guard lock(mutex_);
  return overflow_;
}

void Subscription::closed() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
    wake_ = nullptr;
  }
  hub_.remove(this);
}

std::size_t Subscription::pending() const {
  std::lock_guard lock(mutex_);
  return queue_.size() - head_;
}

std::size_t Subscription::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace salient::server
