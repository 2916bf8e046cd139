// NodePresence: this node's place in a farm (several salientd on one PostgreSQL): its row in
// `nodes`, renewed every lease/3 (a node whose heartbeat is older than the lease is dead), and its
// printers' rows in `farm_printers`, rewritten when a printer changes (at most every
// kStatusInterval each). All of it on the presence's own thread and database connection: a
// printer's streaming thread only marks its printer changed (a set under a mutex), never waits on
// the database. The same thread, once a second, marks the running prints of dead nodes'
// printers interrupted and calls the tick (the farm queue's catch-up: PrinterService::farm_tick).
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "server/printers/printer_service.hpp"
#include "server/store/store.hpp"

namespace salient::server {

class NodePresence {
 public:
  struct Options {
    std::string node, roles, version;
    double lease_seconds = 15;
  };
  // `printers` may be null (a node without the printers role); `status` writes a printer's status
  // as GET /api/v1/printers/{id} gives it.
  NodePresence(Store& store, Options options, PrinterService* printers,
               std::function<std::string(const Printer&)> status);
  ~NodePresence();
  NodePresence(const NodePresence&) = delete;
  NodePresence& operator=(const NodePresence&) = delete;

  // The first heartbeat and the printers' registration, on the calling thread: StoreError when a
  // printer id is another live node's. Then the thread.
  void start(std::function<void()> tick = {});
  void stop();
  void changed(const Printer& printer);  // from any thread; never blocks on the database

  static constexpr std::chrono::milliseconds kStatusInterval{250};

 private:
  void run();
  void heartbeat(double now);
  void register_printers(double now);
  void write_statuses();

  Store& store_;
  Options options_;
  PrinterService* printers_;
  std::function<std::string(const Printer&)> status_;
  std::function<void()> tick_;
  double started_at_ = 0;
  bool registered_ = true;  // the printers' rows are there (false: forgotten, not yet again)

  std::mutex mutex_;
  std::condition_variable wake_;
  std::set<std::string> dirty_;  // printers changed since their row was written
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace salient::server
