// PrinterService: the configured printers, what they print (a finished job's G-code, an uploaded
// file, or the rest of an interrupted print), and where their changes go (the API publishes them
// on the hub as "printers", "printer/ID" and "terminal/ID" events: printer_event_publisher), and
// each printer's temperatures over the last half hour.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "server/config/daemon_config.hpp"
#include "server/printers/printer.hpp"
#include "server/printers/temperature_history.hpp"
#include "server/store/queue_store.hpp"
#include "server/store/store.hpp"

namespace salient::server {

// What becomes of printers' changes (every hook may be empty).
struct PrinterEvents : Printer::Hooks {
  // A printer's queue changed (an entry added, removed, moved or started): its entries now.
  std::function<void(const Printer&, const std::vector<QueueEntry>&)> queue_changed;
};

// What a print request became: a print started now, or an entry waiting in the printer's queue.
struct PrintSubmission {
  long long print = 0;
  std::optional<QueueEntry> queued;
};

class PrinterService {
 public:
  // Marks prints a previous run left unfinished as interrupted.
  PrinterService(const DaemonConfig& config, Store& store, PrinterEvents events = {});
  ~PrinterService();

  void start();  // every printer's thread (autoconnect ones connect)
  void stop();

  Printer& get(const std::string& id);  // NotFound
  const std::vector<std::unique_ptr<Printer>>& all() const { return printers_; }
  Printer* first() { return printers_.empty() ? nullptr : printers_.front().get(); }

  // NotFound: no such job/file/print; Conflict: job not done or printer busy.
  long long print_job(Printer& printer, const std::string& job_id);
  long long print_file(Printer& printer, const std::string& name);
  long long resume(Printer& printer, long long print_id);

  // The print queue (printer_queue.cpp). A job or file prints at once on an idle printer with
  // nothing waiting; it is queued while the printer prints (or pauses, or cancels) or others
  // wait. The next starts on next(), the bed declared clear, or by itself when a print ends on
  // a printer with auto_start. NotFound: no such job/file; Conflict: job not done, or an idle
  // printer that cannot print (not connected).
  PrintSubmission submit_job(Printer& printer, const std::string& job_id);
  PrintSubmission submit_file(Printer& printer, const std::string& name);
  std::vector<QueueEntry> queue(const Printer& printer);
  // Starts the first entry: (print id, entry). Conflict: nothing queued, or the printer not idle.
  // An entry that can no longer print (its job or file deleted) is dropped, and the error told.
  std::pair<long long, QueueEntry> next(Printer& printer);
  void remove_queued(Printer& printer, long long entry);                    // NotFound
  void move_queued(Printer& printer, long long entry, long long position);  // NotFound, BadRequest

  // The printer's temperatures, sampled whenever it reports (once a second at most). NotFound.
  const TemperatureHistory& temperatures(const std::string& id) const;

 private:
  PrintSubmission submit(Printer& printer, const std::string& kind, const std::string& ref);
  long long start_entry(Printer& printer, const std::string& kind, const std::string& ref);
  void check_printable(const std::string& kind, const std::string& ref);
  void auto_start(Printer& printer);
  void queue_changed(const Printer& printer);

  Store& store_;
  std::function<void(const Printer&, const std::vector<QueueEntry>&)> queue_changed_;
  // Serializes queue decisions (check, then start or queue). Recursive: starting a print
  // notifies, and that notification may come back here on the same thread.
  std::recursive_mutex queue_mutex_;
  std::map<std::string, std::unique_ptr<TemperatureHistory>> temperatures_;  // fixed after construction
  std::vector<std::unique_ptr<Printer>> printers_;
};

}  // namespace salient::server
