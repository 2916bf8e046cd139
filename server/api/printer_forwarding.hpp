// Printers across nodes (a farm on one PostgreSQL). PrinterFarm is the API node's side: the other
// nodes' printers from the registry (FarmStore), and a request for one of them carried through
// the database to the node that owns it (a row in printer_requests), its answer awaited: 503
// when that node is dead (its heartbeat older than the lease), 504 when it does not take it in
// time (the request is then withdrawn: it never runs late); a request it took but answers slowly
// is awaited as long again, then 504 saying it may still happen. PrinterRequestExecutor is the owning
// node's side: it takes the requests for this node (woken by a NOTIFY from the API node; polling
// an index every kIdlePoll in case one is lost, every kPoll on SQLite) and runs each
// through this node's Router as the caller it names, who was authenticated where it came in.
#pragma once

#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/http/router.hpp"
#include "server/store/farm_store.hpp"
#include "server/store/store.hpp"

namespace salient::server {

class PrinterFarm {
 public:
  struct Options {
    std::string node;
    double lease_seconds = 15;
    double timeout_seconds = 10;              // for a forwarded request to be answered (or taken)
    std::size_t max_body_bytes = 256u << 10;  // a forwarded body (G-code goes through the files routes)
    // Handlers run on the HTTP server's threads, and a forwarded request holds one while it waits:
    // beyond this many waiting at once, 503 with Retry-After, so that a frozen node cannot take
    // every thread (keep it below the server's thread count).
    int max_waiting = 6;
  };
  PrinterFarm(Store& store, Options options) : store_(store), options_(std::move(options)) {}

  const std::string& node() const { return options_.node; }
  // The printers of other nodes, with whether their node is live.
  std::vector<FarmPrinter> others();
  std::optional<FarmPrinter> other(const std::string& id);  // another node's printer
  bool live(const FarmPrinter& p) const;
  bool profile_live(const std::string& profile);  // a live node (this one or another) has one
  // Carries `request` to the node of `printer` and returns its answer (or the 413, 503, 504).
  HttpResponse forward(const HttpRequest& request, const FarmPrinter& printer);

 private:
  double now() const;
  HttpResponse carry(const HttpRequest& request, const FarmPrinter& printer);
  Store& store_;
  Options options_;
  std::atomic<int> waiting_{0};
};

class PrinterRequestExecutor {
 public:
  static constexpr std::chrono::milliseconds kPoll{50};        // SQLite, or PostgreSQL away
  static constexpr std::chrono::milliseconds kIdlePoll{1000};  // PostgreSQL: woken by NOTIFY
  PrinterRequestExecutor(Store& store, const Router& router, std::string node);
  ~PrinterRequestExecutor();
  void start();
  void stop();
  // One request as this node's router answers it for `caller` (no key checked: the API node did).
  static HttpResponse run(const Router& router, const PrinterRequest& request);

 private:
  void loop();
  Store& store_;
  const Router& router_;
  std::string node_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace salient::server
