// EventRelay: see the header for order, size and reconnection. A notification's payload is a
// RelayedEvent's text (relayed_event.hpp), or "@ID", the row of event_payloads that holds it.
#include "server/events/event_relay.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

namespace salient::server {
namespace {

using Clock = std::chrono::steady_clock;

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool job_topic(const std::vector<std::string>& topics) {
  return std::any_of(topics.begin(), topics.end(),
                     [](const std::string& t) { return t == "jobs" || t.rfind("job/", 0) == 0; });
}

struct Pending {
  std::vector<std::string> topics;
  std::string type, data_json;
  Delivery delivery;
  bool interest = false;  // not an event: "this node has subscribers to `topics`"
};

// Topics whose events are only made while someone subscribes (EventHub::has_subscribers): the
// nodes tell each other of their subscribers to these.
bool wanted_topic(const std::string& topic) {
  return topic.rfind("terminal/", 0) == 0;
}

}  // namespace

struct EventRelay::State {
  State(DatabaseUrl u, EventHub& h, ThreadDatabase t, EventRelayOptions o, Log l)
      : url(std::move(u)), hub(h), thread_db(std::move(t)), options(std::move(o)), log(std::move(l)) {}

  DatabaseUrl url;
  EventHub& hub;
  ThreadDatabase thread_db;
  EventRelayOptions options;
  Log log;
  std::vector<std::function<void(const RelayedEvent&)>> observers;

  std::atomic<std::uint64_t> seq{0};
  mutable std::mutex mutex;  // the queue, the stats, running
  std::condition_variable wake;
  std::deque<Pending> queue;
  EventRelayStats stats;
  bool running = false, stopping = false;
  std::atomic<bool> listening{false};
  bool observing = false;  // under mutex; false once the listener has stopped
  std::map<std::string, Clock::time_point> remote_interest;  // wanted topic → until when (mutex)
  std::unique_ptr<Database> listener_db;
  std::deque<RelayedEvent> observed;  // waiting for the observers
  std::condition_variable observed_wake;
  std::thread sender, listener, observer;

  void note(const std::string& text) {
    if (log) log(text);
  }

  // Sends one event on `db` (inside its transaction, if one is open): NOTIFY, with the text in
  // event_payloads first if it is too large for one.
  void send(Database& db, const Pending& p) { db.notify(options.channel, fit(db, text_of(p))); }

  std::string text_of(const Pending& p) {
    return p.interest ? encode_interest(options.node, ++seq, p.topics)
                      : encode_event(options.node, ++seq, p.topics, p.type, p.data_json, p.delivery);
  }
  // The payload that carries `text`: itself, or "@ID" once a text too large for a notification is
  // stored (on `db`, in its transaction if one is open).
  std::string fit(Database& db, std::string text) {
    if (text.size() <= Database::kMaxNotifyPayload) return text;
    auto q = db.prepare("INSERT INTO event_payloads (body, created_at) VALUES (?, ?) RETURNING id");
    q.bind(1, std::string_view(text)).bind(2, unix_now());
    if (!q.step()) throw StoreError("event_payloads: no id returned");
    const std::int64_t id = q.integer(0);
    q.run();
    std::lock_guard lock(mutex);
    ++stats.stored;
    std::string payload = "@";  // appended, not "@" + …: GCC 12 warns falsely (-Wrestrict) on that
    payload += std::to_string(id);
    return payload;
  }

  // A batch in one statement, one round trip (and one commit): pg_notify over an array, in its
  // order. With a large event stored first, both go in one transaction.
  void send_many(Database& db, const std::vector<Pending>& batch) {
    std::string array = "{";
    bool open = false;
    for (const Pending& p : batch) {
      std::string text = text_of(p);
      if (text.size() > Database::kMaxNotifyPayload && !open) db.exec("BEGIN"), open = true;
      text = fit(db, std::move(text));
      array += array.size() > 1 ? ",\"" : "\"";
      for (char c : text) {
        if (c == '"' || c == '\\') array += '\\';
        array += c;
      }
      array += '"';
    }
    array += '}';
    auto q = db.prepare("SELECT pg_notify(?, x) FROM unnest(CAST(? AS TEXT[])) AS u(x)");
    q.bind(1, std::string_view(options.channel)).bind(2, std::string_view(array));
    q.run();
    if (open) db.exec("COMMIT");
  }

  void enqueue(Pending p) {
    {
      std::lock_guard lock(mutex);
      if (p.delivery == Delivery::coalesce) {
        // The newest unsent event about the same subject: progress replaces progress; a state
        // change stops the search, so that the order around it is kept.
        for (auto it = queue.rbegin(); it != queue.rend(); ++it) {
          if (it->topics.back() != p.topics.back()) continue;
          if (it->delivery != Delivery::coalesce) break;
          *it = std::move(p);
          ++stats.coalesced;
          return;
        }
      }
      if (p.delivery != Delivery::always && queue.size() >= options.queue_limit) {
        ++stats.dropped;
        return;
      }
      queue.push_back(std::move(p));
    }
    wake.notify_all();
  }

  void observe(RelayedEvent e) {
    if (observers.empty()) return;
    {
      std::lock_guard lock(mutex);
      if (e.delivery != Delivery::always && observed.size() >= options.queue_limit) return;
      observed.push_back(std::move(e));
    }
    observed_wake.notify_all();
  }
  void run_observers() {
    for (;;) {
      RelayedEvent e;
      {
        std::unique_lock lock(mutex);
        observed_wake.wait(lock, [&] { return !observed.empty() || !observing; });
        if (observed.empty()) return;
        e = std::move(observed.front());
        observed.pop_front();
      }
      for (const auto& o : observers) {
        try {
          o(e);
        } catch (const std::exception& ex) {
          note(std::string("event relay: an observer failed: ") + ex.what());
        }
      }
    }
  }

  // Tells the other nodes of this node's subscribers to wanted topics, at most 80 a notification.
  void announce(const std::vector<std::string>& topics) {
    for (std::size_t at = 0; at < topics.size(); at += 80) {
      Pending p;
      p.topics.assign(topics.begin() + static_cast<std::ptrdiff_t>(at),
                      topics.begin() + static_cast<std::ptrdiff_t>(std::min(topics.size(), at + 80)));
      p.delivery = Delivery::always;
      p.interest = true;
      enqueue(std::move(p));
    }
  }
  void announce_all() {
    std::vector<std::string> topics;
    for (const std::string& t : hub.topics())
      if (wanted_topic(t)) topics.push_back(t);
    announce(topics);
  }
  bool interested(const std::string& topic) {
    std::lock_guard lock(mutex);
    const auto it = remote_interest.find(topic);
    return it != remote_interest.end() && it->second > Clock::now();
  }
  void note_interest(const std::vector<std::string>& topics) {
    const auto until = Clock::now() + 3 * options.interest_interval;
    std::lock_guard lock(mutex);
    std::erase_if(remote_interest, [](const auto& kv) { return kv.second < Clock::now(); });
    for (const std::string& t : topics)
      if (wanted_topic(t) && remote_interest.size() < 100000) remote_interest[t] = until;
  }

  void send_batch(std::unique_ptr<Database>& db, const std::vector<Pending>& batch);
  void send_again(std::unique_ptr<Database>& db, const Pending& p);
  void sweep(Database& db);
  void run_sender();
  void run_listener();
  void receive(Database& db, const Database::Notification& n);
  bool pause(std::chrono::milliseconds d) {  // false: stopping
    std::unique_lock lock(mutex);
    return !wake.wait_for(lock, d, [&] { return stopping; });
  }
};

// One statement per batch: one round trip and one commit for many events. (A large event alone is
// stored, then notified, in two commits: the row is there before anyone hears of it.) After a failure the
// events are sent again one by one, each on a working connection: twice rather than never (the
// commit may have happened unseen). One that fails twice on a fresh connection is given up, so
// that an event the database refuses cannot block those behind it.
void EventRelay::State::send_batch(std::unique_ptr<Database>& db, const std::vector<Pending>& batch) {
  try {
    if (!db) db = std::make_unique<Database>(url);
    if (batch.size() == 1)
      send(*db, batch.front());
    else
      send_many(*db, batch);
    std::lock_guard lock(mutex);
    stats.sent += batch.size();
    return;
  } catch (const std::exception& e) {
    note("event relay: sending " + std::to_string(batch.size()) + " event(s) failed (" + e.what() +
         "); sending them again");
    db.reset();
  }
  for (const Pending& p : batch) send_again(db, p);
}

void EventRelay::State::send_again(std::unique_ptr<Database>& db, const Pending& p) {
  auto backoff = std::chrono::milliseconds(100);
  for (int failures = 0, unreachable = 0;;) {
    try {
      if (!db) db = std::make_unique<Database>(url);
    } catch (const std::exception& e) {
      bool stop;
      {
        std::lock_guard lock(mutex);
        stop = stopping;
      }
      if (unreachable++ == 0 || stop) note(std::string("event relay: cannot connect: ") + e.what());
      if (stop && unreachable > 3) return;
      std::this_thread::sleep_for(backoff);
      backoff = std::min(backoff * 2, std::chrono::milliseconds(5000));
      continue;
    }
    try {
      send(*db, p);
      std::lock_guard lock(mutex);
      ++stats.sent;
      return;
    } catch (const std::exception& e) {
      db.reset();
      if (++failures < 2) continue;
      note("event relay: an event given up (topic " + p.topics.back() + "): " + e.what());
      std::lock_guard lock(mutex);
      ++stats.dropped;
      return;
    }
  }
}

void EventRelay::State::sweep(Database& db) {
  try {
    auto q = db.prepare("DELETE FROM event_payloads WHERE created_at < ?");
    q.bind(1, unix_now() - static_cast<double>(options.payload_retention.count()));
    q.run();
  } catch (const std::exception& e) {
    note(std::string("event relay: sweeping event_payloads failed: ") + e.what());
  }
}

void EventRelay::State::run_sender() {
  std::unique_ptr<Database> db;
  auto next_sweep = Clock::now(), next_announce = Clock::now() + options.interest_interval;
  for (;;) {
    if (Clock::now() >= next_announce) {
      announce_all();
      next_announce = Clock::now() + options.interest_interval;
    }
    std::vector<Pending> batch;
    {
      std::unique_lock lock(mutex);
      wake.wait_until(lock, next_announce, [&] { return stopping || !queue.empty(); });
      if (queue.empty() && stopping) break;
      while (!queue.empty() && batch.size() < options.batch_limit) {
        batch.push_back(std::move(queue.front()));
        queue.pop_front();
      }
    }
    if (!batch.empty()) send_batch(db, batch);
    if (db && Clock::now() >= next_sweep) {
      sweep(*db);
      next_sweep = Clock::now() + std::chrono::seconds(60);
    }
  }
}

void EventRelay::State::receive(Database& db, const Database::Notification& n) {
  std::string text = n.payload;
  if (!text.empty() && text[0] == '@') {
    auto q = db.prepare("SELECT body FROM event_payloads WHERE id = ?");
    q.bind(1, static_cast<std::int64_t>(std::stoll(text.substr(1))));
    if (!q.step()) throw std::invalid_argument("event_payloads row " + text.substr(1) + " is gone");
    text = q.text(0);
    q.run();
  }
  RelayMessage m = decode_relay_message(text, options.node);
  if (!m.event) return note_interest(m.interest);
  RelayedEvent& e = *m.event;
  {
    std::lock_guard lock(mutex);
    ++stats.received;
  }
  hub.deliver(e.topics, e.type, e.data_json, e.delivery);
  observe(std::move(e));
}

void EventRelay::State::run_listener() {
  auto backoff = std::chrono::milliseconds(100);
  auto idle_since = Clock::now();
  while (listening) {
    try {
      if (!listener_db) {
        listener_db = std::make_unique<Database>(url);
        listener_db->listen(options.channel);
        note("event relay: listening again; subscribers are sent the current state (resync)");
        hub.resync("this node lost its connection to the database for a while: events may be missing");
        backoff = std::chrono::milliseconds(100);
      }
      const auto n = listener_db->wait_notification(std::chrono::milliseconds(200));
      if (!n) {
        // A connection that died without a word (a cable, a firewall) shows only when used.
        if (Clock::now() - idle_since > options.ping_interval) {
          listener_db->exec("SELECT 1");
          idle_since = Clock::now();
        }
        continue;
      }
      idle_since = Clock::now();
      try {
        receive(*listener_db, *n);
      } catch (const StoreError&) {
        throw;
      } catch (const std::exception& e) {
        note(std::string("event relay: a notification skipped: ") + e.what());
      }
    } catch (const std::exception& e) {
      note(std::string("event relay: the listening connection failed (") + e.what() + "); reconnecting");
      listener_db.reset();
      {
        std::lock_guard lock(mutex);
        ++stats.reconnects;
      }
      if (!pause(backoff)) break;
      backoff = std::min(backoff * 2, std::chrono::milliseconds(5000));
    }
  }
}

EventRelay::EventRelay(DatabaseUrl url, EventHub& hub, ThreadDatabase thread_db, EventRelayOptions options,
                       Log log)
    : state_(std::make_unique<State>(std::move(url), hub, std::move(thread_db), std::move(options),
                                     std::move(log))) {}

EventRelay::~EventRelay() {
  stop();
}

void EventRelay::on_event(std::function<void(const RelayedEvent&)> observer) {
  state_->observers.push_back(std::move(observer));
}

void EventRelay::start() {
  State& s = *state_;
  s.listener_db = std::make_unique<Database>(s.url);
  s.listener_db->listen(s.options.channel);  // before anything is published through us
  s.running = true;
  s.listening = true;
  s.observing = true;
  s.sender = std::thread([&s] { s.run_sender(); });
  s.listener = std::thread([&s] { s.run_listener(); });
  s.observer = std::thread([&s] { s.run_observers(); });
  s.hub.set_interest(
      [&s](const std::string& topic) {
        if (wanted_topic(topic)) s.announce({topic});
      },
      [&s](const std::string& topic) { return wanted_topic(topic) && s.interested(topic); });
  s.hub.set_forward([this](const std::vector<std::string>& topics, const std::string& type,
                           const std::string& data_json,
                           Delivery delivery) { publish(topics, type, data_json, delivery); });
}

void EventRelay::stop() {
  State& s = *state_;
  {
    std::lock_guard lock(s.mutex);
    if (!s.running) return;
    s.running = false;
    s.stopping = true;
  }
  s.wake.notify_all();
  if (s.sender.joinable()) s.sender.join();  // it sends what is queued first
  {
    std::lock_guard lock(s.mutex);  // no wake-up lost between an observer's test and its wait
    s.listening = false;
  }
  s.wake.notify_all();
  if (s.listener.joinable()) s.listener.join();
  {
    std::lock_guard lock(s.mutex);
    s.observing = false;
  }
  s.observed_wake.notify_all();
  if (s.observer.joinable()) s.observer.join();  // it finishes what it was given
  s.listener_db.reset();
}

void EventRelay::publish(const std::vector<std::string>& topics, const std::string& type,
                         const std::string& data_json, Delivery delivery) {
  if (topics.empty()) return;
  State& s = *state_;
  Pending p{topics, type, data_json, delivery};
  bool running;
  {
    std::lock_guard lock(s.mutex);
    running = s.running;
  }
  if (running && !job_topic(topics)) return s.enqueue(std::move(p));
  Database& db = s.thread_db();
  try {
    s.send(db, p);
    std::lock_guard lock(s.mutex);
    ++s.stats.sent;
  } catch (const std::exception& e) {
    // Inside a transaction the event shares its fate: it failed, the event is not sent. Else the
    // caller's connection failed: the sender has its own.
    if (db.in_transaction() || !running) {
      s.note(std::string("event relay: a job event not sent: ") + e.what());
      return;
    }
    s.note(std::string("event relay: a job event goes through the sender: ") + e.what());
    s.enqueue(std::move(p));
  }
}

EventRelayStats EventRelay::stats() const {
  std::lock_guard lock(state_->mutex);
  return state_->stats;
}

}  // namespace salient::server
