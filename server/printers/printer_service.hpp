// PrinterService: the configured printers, what they print (a finished job's G-code, an uploaded
// file, or the rest of an interrupted print), and their events on the hub ("printers",
// "printer/ID", "terminal/ID").
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "server/config/daemon_config.hpp"
#include "server/events/event_hub.hpp"
#include "server/printers/printer.hpp"
#include "server/store/store.hpp"

namespace salient::server {

class PrinterService {
 public:
  // Marks prints a previous run left unfinished as interrupted.
  PrinterService(const DaemonConfig& config, Store& store, EventHub& hub);
  ~PrinterService();

  void start();  // every printer's thread (autoconnect ones connect)
  void stop();

  Printer& get(const std::string& id);  // ApiError 404
  const std::vector<std::unique_ptr<Printer>>& all() const { return printers_; }
  Printer* first() { return printers_.empty() ? nullptr : printers_.front().get(); }

  // ApiError: 404 no such job/file/print, 409 job not done or printer busy.
  long long print_job(Printer& printer, const std::string& job_id);
  long long print_file(Printer& printer, const std::string& name);
  long long resume(Printer& printer, long long print_id);

 private:
  Store& store_;
  EventHub& hub_;
  std::vector<std::unique_ptr<Printer>> printers_;
};

}  // namespace salient::server
