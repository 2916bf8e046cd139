// EventRelay: the events of /api/v1/events across the nodes of a PostgreSQL store. EventHub hands
// every published event here instead of delivering it; the relay NOTIFYs it on one channel, and
// one listener per node (a connection of its own) receives every event, its own node's too, and
// delivers it to the local hub. So a subscriber on any node sees every node's events, in order per
// topic, with the hub's delivery rules unchanged.
//
// Order: PostgreSQL delivers notifications in commit order, the same to every listener.
//  - Job events ("jobs", "job/ID") are sent at once on the publishing thread's own connection
//    (Store::db): inside the transaction that changes the job they are sent at its commit, with
//    the row, and not at all on rollback; a job's events come from one thread at a time.
//  - All other events (printers, terminal, files) go through one sender thread with an ordered
//    queue, so that a printer thread never waits for the database. Under backlog the queue folds a
//    progress event into an unsent one about the same subject and drops progress and terminal
//    lines beyond its bound; a state change is never dropped. A batch whose sending failed is sent
//    again on a new connection: a state change may then arrive twice, never not at all (only an
//    event the database itself refuses twice, such as invalid UTF-8, is given up, and logged).
//  - A job event whose sending fails outside a transaction (its connection broke) goes through
//    the sender; inside one it fails with it, as the row does.
// Size: a NOTIFY payload is less than 8000 bytes; a larger event is stored in event_payloads
// (migration 9) and the notification carries its id. Rows older than `payload_retention` go.
// Terminal lines are made only while someone subscribes (EventHub::has_subscribers): each node
// tells the others which terminal topics its subscribers have (a notification of its own, when a
// client subscribes and every interest_interval), and has_subscribers counts those too.
// A lost listening connection: everything NOTIFYed until it is back is missed by this node (this
// node's own events included: they too come back through the database). It reconnects (logged,
// with back-off) and then calls EventHub::resync: each subscriber gets a "resync" event and the
// snapshots of its topics again, i.e. the current state, as on subscribing ("jobs" lists the
// unfinished ones: a job that finished in the gap is no longer among them; a client that cares
// reads GET /api/v1/jobs after a "resync").
// SQLite: no relay; EventHub delivers in-process as it always has.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "server/events/event_hub.hpp"
#include "server/events/relayed_event.hpp"
#include "server/store/database.hpp"

namespace salient::server {

struct EventRelayOptions {
  std::string channel = "salient_events";
  std::string node;                // this node's id, carried by each event (RelayedEvent::local)
  std::size_t queue_limit = 4096;  // queued events beyond which progress and terminal lines drop
  std::size_t batch_limit = 256;   // events the sender sends in one transaction
  std::chrono::seconds payload_retention{600};
  std::chrono::milliseconds ping_interval{5000};  // an idle listener checks its connection this often
  // A node tells the others of its subscribers to terminal topics when they subscribe and this
  // often after; a printer elsewhere sends its lines while told so in the last 3 intervals.
  std::chrono::milliseconds interest_interval{20000};
};

struct EventRelayStats {
  std::uint64_t sent = 0, received = 0, coalesced = 0, dropped = 0, reconnects = 0, stored = 0;
};

class EventRelay {
 public:
  using ThreadDatabase = std::function<Database&()>;
  using Log = std::function<void(const std::string&)>;

  // `url`: a PostgreSQL store; the listener and the sender open connections of their own.
  // `thread_db`: the calling thread's connection (Store::db), on which job events are sent.
  EventRelay(DatabaseUrl url, EventHub& hub, ThreadDatabase thread_db, EventRelayOptions options = {},
             Log log = {});
  ~EventRelay();  // stop()
  EventRelay(const EventRelay&) = delete;
  EventRelay& operator=(const EventRelay&) = delete;

  // Called for every event received (every node's, this one's too: see RelayedEvent::local), in
  // the order received, on a thread of its own, so that a slow observer delays no subscriber.
  // Set before start(). Past `queue_limit` waiting events, observers miss progress and terminal
  // lines, never a state change.
  void on_event(std::function<void(const RelayedEvent&)> observer);
  // Listens (throws StoreError if it cannot connect), starts both threads and makes the hub
  // forward its events here.
  void start();
  // Sends what is queued, then stops both threads. Events published later are sent on the
  // publishing thread's connection (no longer received here).
  void stop();

  void publish(const std::vector<std::string>& topics, const std::string& type, const std::string& data_json,
               Delivery delivery);
  EventRelayStats stats() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace salient::server
