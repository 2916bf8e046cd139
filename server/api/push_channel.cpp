#include "server/api/push_channel.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "server/common/json_text.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

// OctoPrint's reason when a session is unknown (its others: logout, removed, modified).
const std::string kReauth = R"({"reauthRequired":{"reason":"stale"}})";

// {"subscribe": {"state": true | {"logs": …, "messages": …}, "events": true | [types], "plugins": …}}
// as OctoPrint reads it; anything of another shape leaves that part as it was.
void apply_subscription(const json& s, PushSubscription& sub) {
  if (!s.is_object()) return;
  if (const auto it = s.find("state"); it != s.end()) {
    if (it->is_boolean()) {
      sub.state = sub.logs = sub.messages = it->get<bool>();
    } else if (it->is_object()) {
      sub.state = true;
      if (const auto l = it->find("logs"); l != it->end())
        sub.logs = l->is_string() || (l->is_boolean() && l->get<bool>());
      if (const auto m = it->find("messages"); m != it->end())
        sub.messages = m->is_boolean() && m->get<bool>();
    }
  }
  if (const auto it = s.find("events"); it != s.end()) {
    if (it->is_boolean()) {
      sub.all_events = it->get<bool>();
      sub.events.clear();
    } else if (it->is_array()) {
      sub.all_events = false;
      sub.events.clear();
      for (const auto& e : *it)
        if (e.is_string() && sub.events.size() < 256) sub.events.insert(e.get<std::string>());
    }
  }
}

}  // namespace

PushChannel::PushChannel(const PushFeed& feed, std::string connected, PushLimits limits,
                         std::function<Clock::time_point()> clock)
    : feed_(feed), limits_(limits), clock_(std::move(clock)) {
  enqueue({std::move(connected), nullptr});
}

void PushChannel::open(std::function<void()> wake) {
  {
    std::lock_guard lock(mutex_);
    wake_ = wake;
  }
  if (wake) wake();
}

void PushChannel::wake() const {
  std::function<void()> wake;
  {
    std::lock_guard lock(mutex_);
    wake = wake_;
  }
  if (wake) wake();
}

void PushChannel::receive(const std::string& text) {
  json message;
  try {
    message = parse_json_text(text, 8);
  } catch (const std::invalid_argument&) {
    return;  // as OctoPrint: a message that is not JSON is ignored
  }
  if (!message.is_object()) return;
  {
    std::lock_guard lock(mutex_);
    // OctoPrint takes an integer of at least 1 and ignores anything else.
    if (const auto t = message.find("throttle"); t != message.end() && t->is_number_integer() && *t >= 1)
      throttle_ = static_cast<int>(std::min<long long>(t->get<long long>(), limits_.max_throttle));
    if (const auto s = message.find("subscribe"); s != message.end()) apply_subscription(*s, subscription_);
    if (const auto a = message.find("auth"); a != message.end())
      authenticate(a->is_string() ? a->get<std::string>() : std::string());
  }
  wake();
}

void PushChannel::authenticate(const std::string& auth) {
  try {
    user_ = auth.empty() ? std::nullopt : feed_.user_of_auth(auth);
  } catch (const std::runtime_error&) {
    user_.reset();  // not known now: the client is asked to log in again, and retries
  }
  auth_ = user_ ? auth : std::string();
  if (!user_) {
    latest_.reset();
    return enqueue({kReauth, nullptr});
  }
  // History once, then updates from now on (a second auth sends it again, as OctoPrint does).
  latest_.reset();
  if (subscription_.state) enqueue({"{\"history\":" + feed_.history(cursor_, subscription_) + "}", nullptr});
  last_current_ = clock_();
  sent_current_ = true;
}

void PushChannel::enqueue(Item item) {
  if (closed_ || !overflow_.empty()) return;
  const std::size_t size = item.current ? item.current->size() : item.text.size();
  if (queue_.size() >= limits_.max_queued || queued_bytes_ + size > limits_.max_queued_bytes) {
    overflow_ = "too slow: more than " + std::to_string(limits_.max_queued) + " messages or " +
                std::to_string(limits_.max_queued_bytes >> 20) + " MiB waiting";
    queue_.clear();
    queued_bytes_ = 0;
    latest_.reset();
    return;
  }
  queued_bytes_ += size;
  queue_.push_back(std::move(item));
}

void PushChannel::state_changed(std::shared_ptr<const std::string> current) {
  {
    std::lock_guard lock(mutex_);
    if (!user_ || !subscription_.state) return;
    enqueue({{}, std::move(current)});
    latest_.reset();  // the state's own message carries the newest
  }
  wake();
}

void PushChannel::progress(std::shared_ptr<const std::string> current) {
  bool now;
  {
    std::lock_guard lock(mutex_);
    if (!user_ || !subscription_.state) return;
    latest_ = std::move(current);
    now = due_locked(clock_());
  }
  if (now) wake();
}

void PushChannel::event(const std::string& type, const std::string& payload) {
  {
    std::lock_guard lock(mutex_);
    if (!user_ || !subscription_.wants_event(type)) return;
    enqueue({"{\"event\":{\"type\":" + json_text(json(type)) + ",\"payload\":" + payload + "}}", nullptr});
  }
  wake();
}

bool PushChannel::due_locked(Clock::time_point now) const {
  const auto waited = [&](std::chrono::milliseconds interval) {
    return !sent_current_ || now - last_current_ >= interval;
  };
  // A change of state waits its 500 ms too (OctoPrint sends at most two a second): late, never lost.
  if (!queue_.empty()) return !queue_.front().current || waited(limits_.base_interval);
  if (!latest_ || !user_ || !subscription_.state) return false;
  return waited(limits_.base_interval * throttle_);
}

bool PushChannel::due() const {
  std::lock_guard lock(mutex_);
  return !closed_ && (due_locked(clock_()) || !overflow_.empty());
}

bool PushChannel::recheck_session() {
  {
    std::lock_guard lock(mutex_);
    try {
      if (!user_ || closed_ || feed_.user_of_auth(auth_)) return true;
    } catch (const std::runtime_error&) {
      return false;
    }
    user_.reset();
    auth_.clear();
    latest_.reset();
    enqueue({R"({"reauthRequired":{"reason":"removed"}})", nullptr});
  }
  wake();
  return true;
}

bool PushChannel::authenticated() const {
  std::lock_guard lock(mutex_);
  return user_.has_value();
}

bool PushChannel::wants_logs() const {
  std::lock_guard lock(mutex_);
  return !closed_ && user_ && subscription_.state && subscription_.logs;
}

int PushChannel::throttle() const {
  std::lock_guard lock(mutex_);
  return throttle_;
}

std::string PushChannel::compose_current(const std::string& current) {
  std::string out = "{\"current\":";
  out.append(current, 0, current.size() - 1);  // the object without its closing brace
  const std::string backlog = feed_.backlog(cursor_, subscription_);
  if (!backlog.empty()) {
    if (current.size() > 2) out += ',';
    out += backlog;
  }
  out += "}}";
  return out;
}

std::optional<std::string> PushChannel::next() {
  std::lock_guard lock(mutex_);
  if (closed_ || !overflow_.empty()) return std::nullopt;
  const Clock::time_point now = clock_();
  if (!due_locked(now)) return std::nullopt;
  if (!queue_.empty()) {
    Item item = std::move(queue_.front());
    queue_.pop_front();
    queued_bytes_ -= item.current ? item.current->size() : item.text.size();
    if (!item.current) return std::move(item.text);
    last_current_ = now;
    sent_current_ = true;
    return compose_current(*item.current);
  }
  std::shared_ptr<const std::string> current = std::move(latest_);
  latest_.reset();
  last_current_ = now;
  sent_current_ = true;
  return compose_current(*current);
}

std::string PushChannel::close_reason() {
  std::lock_guard lock(mutex_);
  return overflow_;
}

void PushChannel::closed() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  wake_ = nullptr;
  queue_.clear();
  latest_.reset();
}

}  // namespace salient::server
