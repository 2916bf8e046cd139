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
#include <set>
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
  // A queue changed (an entry added, removed, moved or started): its key (a printer id, or
  // "profile/P" for a profile's farm-wide queue) and its entries now.
  std::function<void(const std::string&, const std::vector<QueueEntry>&)> queue_changed;
};

// What a print request became: a print started now, or an entry waiting in the printer's queue.
struct PrintSubmission {
  long long print = 0;
  std::optional<QueueEntry> queued;
  std::string printer;  // where the print started (empty when queued)
};

class PrinterService {
 public:
  // Marks prints a previous run left unfinished as interrupted: all of them on SQLite (one node),
  // only those of its own printers on PostgreSQL (other nodes of the farm may be printing).
  PrinterService(const DaemonConfig& config, Store& store, PrinterEvents events = {});
  ~PrinterService();

  void start();  // every printer's thread (autoconnect ones connect)
  void stop();

  Printer& get(const std::string& id);   // NotFound
  Printer* find(const std::string& id);  // null when not here
  const std::vector<std::unique_ptr<Printer>>& all() const { return printers_; }
  Printer* first() { return printers_.empty() ? nullptr : printers_.front().get(); }

  // NotFound: no such job/file/print; Conflict: job not done or printer busy.
  long long print_job(Printer& printer, const std::string& job_id);
  long long print_file(Printer& printer, const std::string& name);
  long long resume(Printer& printer, long long print_id);

  // The print queues (printer_queue.cpp). A job or file prints at once on an idle printer with
  // nothing ready waiting; it is queued while the printer prints (or pauses, or cancels) or others
  // wait. The next starts on next(), the bed declared clear, or by itself when a print ends on
  // a printer with auto_start. NotFound: no such job/file; Conflict: job not done (unless
  // `when_sliced`: a job still slicing then waits in the queue and starts once it is done, see
  // job_finished), or an idle printer that cannot print (not connected).
  PrintSubmission submit_job(Printer& printer, const std::string& job_id, bool when_sliced = false);
  PrintSubmission submit_file(Printer& printer, const std::string& name);
  // The farm-wide queue of a profile: the print goes to any idle printer with that profile (one
  // with nothing ready in its own queue), else waits until one takes it (its own queue first).
  // NotFound: no printer has the profile.
  PrintSubmission submit_to_profile(const std::string& profile, const std::string& kind,
                                    const std::string& ref, bool when_sliced = false);
  std::vector<QueueEntry> queue(const Printer& printer);
  std::vector<QueueEntry> profile_queue(const std::string& profile);  // NotFound
  // Starts the first entry ready to print, from the printer's queue, else from its profile's:
  // (print id, entry). Conflict: nothing ready, or the printer not idle. An entry that can no
  // longer print (its job failed or was deleted, its file deleted) is dropped, and the error told.
  std::pair<long long, QueueEntry> next(Printer& printer);
  void remove_queued(Printer& printer, long long entry);                    // NotFound
  void move_queued(Printer& printer, long long entry, long long position);  // NotFound, BadRequest
  void remove_from_profile(const std::string& profile, long long entry);    // NotFound
  // A job ended (done, failed or cancelled) or was deleted: entries waiting for it start where a
  // printer is idle and nothing ready is ahead of them, or are dropped if it failed or is gone.
  // Safe for a job finished on another node (only this node's printers start, and an entry is
  // taken out of its queue before it starts: two nodes never start the same one).
  void job_finished(const std::string& job_id);

  // In a farm: whether a live node (another one) has a printer of the profile, so that a
  // profile's farm-wide queue exists here without a printer of it.
  void set_farm_profiles(std::function<bool(const std::string&)> elsewhere) {
    profile_elsewhere_ = std::move(elsewhere);
  }
  // In a farm: whether the printer is another node's (whose queue is then fed here, and started
  // there by its farm_tick).
  void set_farm_printers(std::function<bool(const std::string&)> elsewhere) {
    printer_elsewhere_ = std::move(elsewhere);
  }
  bool has_profile(const std::string& profile);  // a printer here, or on a live node, has it
  bool has_printer(const std::string& id);       // here, or another node's
  // submit_job on this node's printer, or, for another node's, the job waits in that printer's
  // queue (the node starts it when it is sliced and the printer is free). NotFound, Conflict.
  PrintSubmission submit_job_to(const std::string& printer_id, const std::string& job_id, bool when_sliced);
  // In a farm, about once a second: entries added on other nodes, and entries waiting for a job
  // that finished elsewhere, start on this node's idle printers as they would have here.
  void farm_tick();

  // The printer's temperatures, sampled whenever it reports (once a second at most). NotFound.
  const TemperatureHistory& temperatures(const std::string& id) const;

 private:
  enum class Readiness { ready, slicing, gone };
  PrintSubmission submit(Printer& printer, const std::string& kind, const std::string& ref, bool when_sliced);
  long long start_entry(Printer& printer, const std::string& kind, const std::string& ref);
  Readiness readiness(const std::string& kind, const std::string& ref);
  // NotFound, or Conflict for a job not done (slicing is fine when `when_sliced`).
  void check_printable(const std::string& kind, const std::string& ref, bool when_sliced);
  std::vector<QueueEntry> entries(const std::string& key);  // with `slicing` filled in
  bool has_ready(const std::string& key);
  // Starts the first ready entry of `key` on `printer`; nullopt when none is ready. Drops the
  // gone ones; lets a printer_busy Conflict through.
  std::optional<std::pair<long long, QueueEntry>> start_first_ready(Printer& printer, const std::string& key);
  bool idle(Printer& printer);  // operational, with nothing ready in its own queue
  // A print started: the bed holds it until declared clear (next()), unless auto_start says
  // the printer clears its own. Farm-wide entries go only to printers with a clear bed.
  long long occupied(Printer& printer, long long print);
  bool bed_clear(const Printer& printer);
  void dispatch_profile(const std::string& profile);  // idle printers take the profile's entries
  void auto_start(Printer& printer);
  void queue_changed(const std::string& key);
  void queue_changed(const Printer& printer) { queue_changed(printer.id()); }

  // Takes the entry out of its queue before it starts (false: another node or request took it);
  // an entry whose printer turned out busy goes back to its place.
  bool take(const std::string& key, const QueueEntry& e);
  void put_back(const std::string& key, const QueueEntry& e);

  Store& store_;
  std::function<void(const std::string&, const std::vector<QueueEntry>&)> queue_changed_;
  std::function<bool(const std::string&)> profile_elsewhere_, printer_elsewhere_;
  // Serializes queue decisions (check, then start or queue). Recursive: starting a print
  // notifies, and that notification may come back here on the same thread.
  std::recursive_mutex queue_mutex_;
  std::set<std::string> bed_full_;  // printers whose bed holds a print (under queue_mutex_)
  std::map<std::string, std::unique_ptr<TemperatureHistory>> temperatures_;  // fixed after construction
  std::vector<std::unique_ptr<Printer>> printers_;
};

}  // namespace salient::server
