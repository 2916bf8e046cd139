// PrinterService's print queue: requests that found their printer busy wait in the store
// (QueueStore) and start, in order, when the bed is declared clear or, with auto_start, as soon
// as the printer is idle again. See printer_service.hpp.
#include <chrono>

#include "server/common/domain_error.hpp"
#include "server/printers/printer_service.hpp"
#include "server/store/job_store.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {
namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

void PrinterService::check_printable(const std::string& kind, const std::string& ref) {
  if (kind == "job") {
    const auto job = JobStore(store_.db()).get(ref);
    if (!job) throw NotFound("no job " + ref);
    if (job->state != JobState::done || !job->result)
      throw Conflict("not_ready",
                     "job " + ref + " is " + std::string(to_string(job->state)) + ": nothing to print");
  } else if (!PrintStore(store_.db()).file(ref)) {
    throw NotFound("no file '" + ref + "' (upload it to /api/files/local)");
  }
}

long long PrinterService::start_entry(Printer& printer, const std::string& kind, const std::string& ref) {
  return kind == "job" ? print_job(printer, ref) : print_file(printer, ref);
}

PrintSubmission PrinterService::submit_job(Printer& printer, const std::string& job_id) {
  return submit(printer, "job", job_id);
}

PrintSubmission PrinterService::submit_file(Printer& printer, const std::string& name) {
  return submit(printer, "file", name);
}

PrintSubmission PrinterService::submit(Printer& printer, const std::string& kind, const std::string& ref) {
  std::lock_guard lock(queue_mutex_);
  check_printable(kind, ref);
  QueueStore queue(store_.db());
  // Nothing waits and the printer is free: the print goes now, as without a queue (a printer
  // that is not connected still says so).
  if (!busy_printing(printer.state()) && queue.list(printer.id()).empty()) {
    try {
      return {start_entry(printer, kind, ref), std::nullopt};
    } catch (const Conflict&) {
      if (!busy_printing(printer.state())) throw;  // another request started a print meanwhile: queue
    }
  }
  PrintSubmission out;
  out.queued = queue.add(printer.id(), kind, ref, now_seconds());
  queue_changed(printer);
  return out;
}

std::vector<QueueEntry> PrinterService::queue(const Printer& printer) {
  return QueueStore(store_.db()).list(printer.id());
}

std::pair<long long, QueueEntry> PrinterService::next(Printer& printer) {
  std::lock_guard lock(queue_mutex_);
  QueueStore queue(store_.db());
  const std::vector<QueueEntry> entries = queue.list(printer.id());
  if (entries.empty()) throw Conflict("queue_empty", "printer " + printer.id() + " has nothing queued");
  const QueueEntry& first = entries.front();
  long long print = 0;
  try {
    print = start_entry(printer, first.kind, first.ref);
  } catch (const Conflict& e) {
    if (e.code() == "printer_busy") throw;  // the entry stays first in line
    queue.remove(printer.id(), first.id);
    queue_changed(printer);
    throw;
  } catch (const DomainError&) {  // its job or file is gone, or cannot be printed
    queue.remove(printer.id(), first.id);
    queue_changed(printer);
    throw;
  }
  queue.remove(printer.id(), first.id);
  queue_changed(printer);
  return {print, first};
}

void PrinterService::auto_start(Printer& printer) {
  std::lock_guard lock(queue_mutex_);
  // Skips entries that cannot print any more; stops at the first that starts, or when the
  // printer cannot take one.
  while (printer.state() == PrinterState::operational && !queue(printer).empty()) {
    try {
      next(printer);
      return;
    } catch (const Conflict& e) {
      if (e.code() == "printer_busy" || e.code() == "queue_empty") return;
    } catch (const DomainError&) {
    } catch (const std::exception&) {  // a store error: try again at the next change
      return;
    }
  }
}

void PrinterService::remove_queued(Printer& printer, long long entry) {
  std::lock_guard lock(queue_mutex_);
  if (!QueueStore(store_.db()).remove(printer.id(), entry))
    throw NotFound("no entry " + std::to_string(entry) + " in the queue of " + printer.id());
  queue_changed(printer);
}

void PrinterService::move_queued(Printer& printer, long long entry, long long position) {
  std::lock_guard lock(queue_mutex_);
  QueueStore queue(store_.db());
  if (!queue.get(printer.id(), entry))
    throw NotFound("no entry " + std::to_string(entry) + " in the queue of " + printer.id());
  const auto size = static_cast<long long>(queue.list(printer.id()).size());
  if (position < 1 || position > size)
    throw BadRequest("bad_request",
                     "'position' must be 1 to " + std::to_string(size) + ", got " + std::to_string(position));
  queue.move(printer.id(), entry, position);
  queue_changed(printer);
}

void PrinterService::queue_changed(const Printer& printer) {
  if (queue_changed_) queue_changed_(printer, queue(printer));
}

}  // namespace salient::server
