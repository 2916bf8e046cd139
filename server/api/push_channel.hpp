// PushChannel: one client of OctoPrint's push socket (/sockjs/websocket), as FDM Monster, OctoPod
// and OctoPrint's own page use it. The server says {"connected": …} first; the client answers
// {"auth": "name:session"} (a passive login's session; wrong: {"reauthRequired": …}) and may send
// {"throttle": n} and {"subscribe": {…}}. Once authenticated it gets `history` once, then
// `current` at most every 500 ms × throttle, and `event`s.
//
// Delivery. A `current` that carries a change of state (printing → finishing, → cancelling…) is
// queued and always sent, in order, whatever the throttle: FDM Monster ends a print only when it
// sees `finishing` or `cancelling`, which may last milliseconds. Still no two `current`s go out
// less than 500 ms apart (OctoPrint's rate, which clients rely on): a change waits its turn, and
// what was queued behind it (events) with it. Other updates are coalesced: the newest replaces an
// unsent one and goes out when the throttle allows (500 ms × throttle). The queue is bounded
// (count and bytes); a client that lets it fill is closed with a reason rather than grow the server.
//
// Threading: the hub calls state_changed/progress/event from its thread; the WebSocket session
// calls receive/next from its strand; all under mutex_. Time comes from `clock` (tests step it).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "server/http/websocket_channel.hpp"

namespace salient::server {

// Where a client's backlogs (temperatures, terminal lines) have been read up to.
struct PushCursor {
  double temps_after = 0;        // temperature samples after this time (s since the epoch) are new
  std::uint64_t logs_after = 0;  // terminal lines after this sequence number are new
};

// What the client asked for with {"subscribe": …}; everything until it does.
struct PushSubscription {
  bool state = true, logs = true, messages = true;
  bool all_events = true;
  std::set<std::string> events;  // when !all_events: the event types wanted
  bool wants_event(const std::string& type) const { return all_events || events.count(type) > 0; }
};

// What a channel needs from the server (PushHub; tests give their own).
class PushFeed {
 public:
  virtual ~PushFeed() = default;
  // The user a "name:session" belongs to (none: a wrong or stale session). Throws
  // std::runtime_error when it cannot tell (the database away).
  virtual std::optional<std::string> user_of_auth(std::string_view auth) const = 0;
  // The `history` payload (a JSON object's text), and the cursor moved past what it holds.
  virtual std::string history(PushCursor& cursor, const PushSubscription& subscription) const = 0;
  // What a `current` adds to the printer's part: JSON members (`"temps":[…],"logs":[…],…`, no
  // braces) for what is new since `cursor`, which is moved past it.
  virtual std::string backlog(PushCursor& cursor, const PushSubscription& subscription) const = 0;
};

struct PushLimits {
  std::chrono::milliseconds base_interval{500};  // OctoPrint's rate for throttle 1
  int max_throttle = 100;                        // 50 s between updates at most
  std::size_t max_queued = 512;                  // messages waiting to be sent
  std::size_t max_queued_bytes = 8u << 20;
};

class PushChannel : public WebSocketChannel {
 public:
  using Clock = std::chrono::steady_clock;
  // `connected`: the {"connected": …} message, sent first.
  PushChannel(
      const PushFeed& feed, std::string connected, PushLimits limits = {},
      std::function<Clock::time_point()> clock = [] { return Clock::now(); });

  // From the hub. `current` is the printer's part of a `current` message: a JSON object's text
  // (state, job, progress…), shared by every client. Ignored until the client is authenticated.
  void state_changed(std::shared_ptr<const std::string> current);  // always sent, in order
  void progress(std::shared_ptr<const std::string> current);       // coalesced, throttled
  // {"event": {"type", "payload"}}; `payload`: JSON text.
  void event(const std::string& type, const std::string& payload);
  // Something is waiting and may be sent now (the hub's timer wakes such channels).
  bool due() const;
  void wake() const;

  // The session it authenticated with is gone (logged out, its user's keys revoked): it is told
  // {"reauthRequired": {"reason": "removed"}} and gets nothing more until it authenticates again.
  // False: the feed could not tell (the session is kept; ask again later).
  bool recheck_session();
  bool authenticated() const;
  bool wants_logs() const;  // authenticated, subscribed to the terminal's lines
  int throttle() const;

  // WebSocketChannel.
  void open(std::function<void()> wake) override;
  void receive(const std::string& text) override;
  std::optional<std::string> next() override;
  std::string close_reason() override;
  void closed() override;

 private:
  struct Item {
    std::string text;                            // a ready message, or
    std::shared_ptr<const std::string> current;  // the printer's part of a `current`
  };
  void authenticate(const std::string& auth);               // under mutex_
  void enqueue(Item item);                                  // under mutex_
  std::string compose_current(const std::string& current);  // under mutex_
  bool due_locked(Clock::time_point now) const;

  const PushFeed& feed_;
  PushLimits limits_;
  std::function<Clock::time_point()> clock_;
  mutable std::mutex mutex_;
  std::function<void()> wake_;
  std::deque<Item> queue_;
  std::size_t queued_bytes_ = 0;
  std::shared_ptr<const std::string> latest_;  // the newest progress not yet sent
  Clock::time_point last_current_{};
  bool sent_current_ = false;
  std::optional<std::string> user_;
  std::string auth_;  // the "name:session" user_ came from
  int throttle_ = 1;
  PushSubscription subscription_;
  PushCursor cursor_;
  std::string overflow_;
  bool closed_ = false;
};

}  // namespace salient::server
