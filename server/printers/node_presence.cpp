#include "server/printers/node_presence.hpp"

#include <optional>

#include "server/printers/liveness_witness.hpp"
#include "server/store/farm_store.hpp"

namespace salient::server {
NodePresence::NodePresence(Store& store, Options options, PrinterService* printers,
                           std::function<std::string(const Printer&)> status)
    : store_(store), options_(std::move(options)), printers_(printers), status_(std::move(status)) {}

NodePresence::~NodePresence() {
  stop();
}

void NodePresence::start(std::function<void()> tick) {
  tick_ = std::move(tick);
  started_at_ = FarmStore(store_.db()).clock();
  FarmStore(store_.db())
      .heartbeat({options_.node, options_.roles, options_.version, started_at_, started_at_});
  register_printers(started_at_);
  thread_ = std::thread([this] { run(); });
}

void NodePresence::register_printers(double now) {
  std::vector<FarmStore::Registration> rows;
  if (printers_)
    for (const auto& p : printers_->all()) rows.push_back({p->id(), p->config().profile, status_(*p)});
  FarmStore(store_.db()).register_printers(options_.node, rows, now, now - options_.lease_seconds);
}

void NodePresence::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void NodePresence::changed(const Printer& printer) {
  std::lock_guard lock(mutex_);
  dirty_.insert(printer.id());
}

void NodePresence::heartbeat(double now) {
  // Forgotten while away (its row and its printers' deleted): registered again, as at a start.
  // Refused (StoreError, the beat retried) while another live node holds one of its printer ids.
  if (FarmStore(store_.db()).heartbeat({options_.node, options_.roles, options_.version, started_at_, now}))
    registered_ = false;
  if (registered_) return;
  register_printers(now);
  registered_ = true;
}

void NodePresence::write_statuses() {
  std::set<std::string> dirty;
  {
    std::lock_guard lock(mutex_);
    dirty.swap(dirty_);
  }
  if (dirty.empty() || !printers_) return;
  FarmStore farm(store_.db());
  // When, by this host's clock: shown, never compared with another node's.
  const double at =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  for (const std::string& id : dirty) farm.set_status(id, options_.node, status_(printers_->get(id)), at);
}

void NodePresence::run() {
  using clock = std::chrono::steady_clock;
  const auto beat_every =
      std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(options_.lease_seconds / 3));
  auto next_beat = clock::now() + beat_every, next_tick = clock::now() + std::chrono::seconds(1);
  const auto steady_seconds = [] {
    return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
  };
  // A gap of more than a beat between rounds breaks this node's own contact with the database.
  LivenessWitness witness(options_.lease_seconds, options_.lease_seconds / 3);
  witness.start(steady_seconds());
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, kStatusInterval, [this] { return stopping_; });
    if (stopping_) break;
    lock.unlock();
    // A database that is away for a moment costs a missed beat, not the node: the next try may work.
    try {
      write_statuses();
      // Heartbeats and liveness on the database's clock, read once for both: hosts whose clocks
      // disagree must still agree on who is alive.
      std::optional<double> db_now;
      const auto now = [&] { return db_now ? *db_now : *(db_now = FarmStore(store_.db()).clock()); };
      if (clock::now() >= next_beat) {
        heartbeat(now());
        next_beat = clock::now() + beat_every;
      }
      witness.reached(steady_seconds());
      if (clock::now() >= next_tick) {
        if (witness.may_judge(steady_seconds()))
          FarmStore(store_.db()).interrupt_dead(options_.node, now() - options_.lease_seconds, now());
        if (tick_) tick_();
        next_tick = clock::now() + std::chrono::seconds(1);
      }
    } catch (const std::exception&) {
      witness.failed();
    }
    lock.lock();
  }
}

}  // namespace salient::server
