#include "server/printers/node_presence.hpp"

#include "server/store/farm_store.hpp"

namespace salient::server {
namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

NodePresence::NodePresence(Store& store, Options options, PrinterService* printers,
                           std::function<std::string(const Printer&)> status)
    : store_(store), options_(std::move(options)), printers_(printers), status_(std::move(status)) {}

NodePresence::~NodePresence() {
  stop();
}

void NodePresence::start(std::function<void()> tick) {
  tick_ = std::move(tick);
  started_at_ = now_seconds();
  heartbeat(started_at_);
  std::vector<FarmStore::Registration> rows;
  if (printers_)
    for (const auto& p : printers_->all()) rows.push_back({p->id(), p->config().profile, status_(*p)});
  FarmStore(store_.db())
      .register_printers(options_.node, rows, started_at_, started_at_ - options_.lease_seconds);
  thread_ = std::thread([this] { run(); });
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
  FarmStore(store_.db()).heartbeat({options_.node, options_.roles, options_.version, started_at_, now});
}

void NodePresence::write_statuses(double now) {
  std::set<std::string> dirty;
  {
    std::lock_guard lock(mutex_);
    dirty.swap(dirty_);
  }
  if (dirty.empty() || !printers_) return;
  FarmStore farm(store_.db());
  for (const std::string& id : dirty) farm.set_status(id, options_.node, status_(printers_->get(id)), now);
}

void NodePresence::run() {
  using clock = std::chrono::steady_clock;
  const auto beat_every =
      std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(options_.lease_seconds / 3));
  auto next_beat = clock::now() + beat_every, next_tick = clock::now() + std::chrono::seconds(1);
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, kStatusInterval, [this] { return stopping_; });
    if (stopping_) break;
    lock.unlock();
    // A database that is away for a moment costs a missed beat, not the node: the next try may work.
    try {
      const double now = now_seconds();
      write_statuses(now);
      if (clock::now() >= next_beat) {
        heartbeat(now);
        next_beat = clock::now() + beat_every;
      }
      if (clock::now() >= next_tick) {
        FarmStore(store_.db()).interrupt_dead(options_.node, now - options_.lease_seconds, now);
        if (tick_) tick_();
        next_tick = clock::now() + std::chrono::seconds(1);
      }
    } catch (const std::exception&) {
    }
    lock.lock();
  }
}

}  // namespace salient::server
