// PrinterService: the configured printers, what they print (a finished job's G-code, an uploaded
// file, or the rest of an interrupted print), and where their changes go (the API publishes them
// on the hub as "printers", "printer/ID" and "terminal/ID" events: printer_event_publisher), and
// each printer's temperatures over the last half hour.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "server/config/daemon_config.hpp"
#include "server/printers/printer.hpp"
#include "server/printers/temperature_history.hpp"
#include "server/store/store.hpp"

namespace salient::server {

// What becomes of printers' changes (every hook may be empty).
using PrinterEvents = Printer::Hooks;

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

  // The printer's temperatures, sampled whenever it reports (once a second at most). NotFound.
  const TemperatureHistory& temperatures(const std::string& id) const;

 private:
  Store& store_;
  std::map<std::string, std::unique_ptr<TemperatureHistory>> temperatures_;  // fixed after construction
  std::vector<std::unique_ptr<Printer>> printers_;
};

}  // namespace salient::server
