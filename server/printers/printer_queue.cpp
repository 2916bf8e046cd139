// PrinterService's print queues: requests that found their printer busy wait in the store
// (QueueStore) and start, in order, when the bed is declared clear or, with auto_start, as soon
// as the printer is idle again. A profile's farm-wide queue ("profile/P") feeds whichever printer
// with that profile is idle; a job submitted to print once sliced waits in a queue as "slicing"
// and is passed over until it is done. See printer_service.hpp.
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

std::string profile_key(const std::string& profile) {
  return "profile/" + profile;
}

}  // namespace

PrinterService::Readiness PrinterService::readiness(const std::string& kind, const std::string& ref) {
  if (kind == "file") return PrintStore(store_.db()).file(ref) ? Readiness::ready : Readiness::gone;
  const auto job = JobStore(store_.db()).get(ref);
  if (!job) return Readiness::gone;
  if (job->state == JobState::queued || job->state == JobState::running) return Readiness::slicing;
  return job->state == JobState::done && job->result ? Readiness::ready : Readiness::gone;
}

void PrinterService::check_printable(const std::string& kind, const std::string& ref, bool when_sliced) {
  if (kind == "job") {
    const auto job = JobStore(store_.db()).get(ref);
    if (!job) throw NotFound("no job " + ref);
    const Readiness r = readiness(kind, ref);
    if (r == Readiness::gone || (r == Readiness::slicing && !when_sliced))
      throw Conflict("not_ready",
                     "job " + ref + " is " + std::string(to_string(job->state)) + ": nothing to print");
  } else if (!PrintStore(store_.db()).file(ref)) {
    throw NotFound("no file '" + ref + "' (upload it to /api/files/local)");
  }
}

long long PrinterService::start_entry(Printer& printer, const std::string& kind, const std::string& ref) {
  return kind == "job" ? print_job(printer, ref) : print_file(printer, ref);
}

std::vector<QueueEntry> PrinterService::entries(const std::string& key) {
  std::vector<QueueEntry> out = QueueStore(store_.db()).list(key);
  for (QueueEntry& e : out) e.slicing = readiness(e.kind, e.ref) == Readiness::slicing;
  return out;
}

bool PrinterService::has_ready(const std::string& key) {
  for (const QueueEntry& e : QueueStore(store_.db()).list(key))
    if (readiness(e.kind, e.ref) == Readiness::ready) return true;
  return false;
}

long long PrinterService::occupied(Printer& printer, long long print) {
  std::lock_guard lock(queue_mutex_);
  if (!printer.config().auto_start) bed_full_.insert(printer.id());
  return print;
}

bool PrinterService::bed_clear(const Printer& printer) {
  std::lock_guard lock(queue_mutex_);
  return printer.config().auto_start || !bed_full_.count(printer.id());
}

bool PrinterService::idle(Printer& printer) {
  return printer.state() == PrinterState::operational && !has_ready(printer.id());
}

PrintSubmission PrinterService::submit_job(Printer& printer, const std::string& job_id, bool when_sliced) {
  return submit(printer, "job", job_id, when_sliced);
}

PrintSubmission PrinterService::submit_file(Printer& printer, const std::string& name) {
  return submit(printer, "file", name, false);
}

PrintSubmission PrinterService::submit(Printer& printer, const std::string& kind, const std::string& ref,
                                       bool when_sliced) {
  std::lock_guard lock(queue_mutex_);
  check_printable(kind, ref, when_sliced);
  // Asking a free printer to print declares its bed clear, as a direct print does, whether it
  // prints now or once sliced (if another print comes first, the bed must be declared clear again).
  if (printer.state() == PrinterState::operational && !has_ready(printer.id())) bed_full_.erase(printer.id());
  // Ready, nothing ready waits and the printer is free: the print goes now, as without a queue
  // (a printer that is not connected still says so).
  if (readiness(kind, ref) == Readiness::ready && !busy_printing(printer.state()) &&
      !has_ready(printer.id())) {
    try {
      return {start_entry(printer, kind, ref), std::nullopt, printer.id()};
    } catch (const Conflict&) {
      if (!busy_printing(printer.state())) throw;  // another request started a print meanwhile: queue
    }
  }
  PrintSubmission out;
  out.queued = QueueStore(store_.db()).add(printer.id(), kind, ref, now_seconds());
  out.queued->slicing = readiness(kind, ref) == Readiness::slicing;
  queue_changed(printer);
  return out;
}

PrintSubmission PrinterService::submit_to_profile(const std::string& profile, const std::string& kind,
                                                  const std::string& ref, bool when_sliced) {
  std::lock_guard lock(queue_mutex_);
  profile_queue(profile);  // NotFound when no printer has it
  check_printable(kind, ref, when_sliced);
  // Ready, and nothing ready waits in the profile's queue: the first idle printer takes it now.
  if (readiness(kind, ref) == Readiness::ready && !has_ready(profile_key(profile))) {
    for (auto& p : printers_) {
      if (p->config().profile != profile || !idle(*p) || !bed_clear(*p)) continue;
      try {
        return {start_entry(*p, kind, ref), std::nullopt, p->id()};
      } catch (const Conflict& e) {
        if (e.code() != "printer_busy") throw;  // else another request took this printer: the next
      }
    }
  }
  PrintSubmission out;
  out.queued = QueueStore(store_.db()).add(profile_key(profile), kind, ref, now_seconds());
  out.queued->slicing = readiness(kind, ref) == Readiness::slicing;
  queue_changed(profile_key(profile));
  return out;
}

bool PrinterService::has_profile(const std::string& profile) {
  for (const auto& p : printers_)
    if (p->config().profile == profile) return true;
  return profile_elsewhere_ && profile_elsewhere_(profile);
}

bool PrinterService::has_printer(const std::string& id) {
  return find(id) || (printer_elsewhere_ && printer_elsewhere_(id));
}

PrintSubmission PrinterService::submit_job_to(const std::string& printer_id, const std::string& job_id,
                                              bool when_sliced) {
  if (Printer* here = find(printer_id)) return submit_job(*here, job_id, when_sliced);
  if (!printer_elsewhere_ || !printer_elsewhere_(printer_id))
    throw NotFound("no printer '" + printer_id + "'");
  std::lock_guard lock(queue_mutex_);
  check_printable("job", job_id, when_sliced);
  PrintSubmission out;
  out.queued = QueueStore(store_.db()).add(printer_id, "job", job_id, now_seconds());
  out.queued->slicing = readiness("job", job_id) == Readiness::slicing;
  queue_changed(printer_id);
  return out;
}

std::vector<QueueEntry> PrinterService::queue(const Printer& printer) {
  return entries(printer.id());
}

std::vector<QueueEntry> PrinterService::profile_queue(const std::string& profile) {
  for (const auto& p : printers_)
    if (p->config().profile == profile) return entries(profile_key(profile));
  if (profile_elsewhere_ && profile_elsewhere_(profile)) return entries(profile_key(profile));
  throw NotFound("no printer has the profile '" + profile + "'");
}

std::optional<std::pair<long long, QueueEntry>> PrinterService::start_first_ready(Printer& printer,
                                                                                  const std::string& key) {
  for (const QueueEntry& e : QueueStore(store_.db()).list(key)) {
    const Readiness r = readiness(e.kind, e.ref);
    if (r == Readiness::slicing) continue;  // passed over until it is sliced
    if (!take(key, e)) continue;            // another node started it
    long long print = 0;
    try {
      if (r == Readiness::gone) check_printable(e.kind, e.ref, false);  // throws: why it is gone
      print = start_entry(printer, e.kind, e.ref);
    } catch (const Conflict& error) {
      if (error.code() == "printer_busy") put_back(key, e);  // the entry stays in line
      throw;
    }  // any other error (its job or file is gone, or cannot be printed): it stays out
    return std::pair{print, e};
  }
  return std::nullopt;
}

bool PrinterService::take(const std::string& key, const QueueEntry& e) {
  if (!QueueStore(store_.db()).remove(key, e.id)) return false;  // one DELETE: one taker
  queue_changed(key);
  return true;
}

void PrinterService::put_back(const std::string& key, const QueueEntry& e) {
  QueueStore queue(store_.db());
  const QueueEntry again = queue.add(key, e.kind, e.ref, e.created_at);
  queue.move(key, again.id, e.position);
  queue_changed(key);
}

void PrinterService::farm_tick() {
  std::lock_guard lock(queue_mutex_);
  std::set<std::string> profiles, jobs;
  for (const auto& p : printers_) {
    profiles.insert(p->config().profile);
    for (const QueueEntry& e : QueueStore(store_.db()).list(p->id()))
      if (e.kind == "job") jobs.insert(e.ref);
  }
  for (const std::string& profile : profiles) dispatch_profile(profile);
  for (const std::string& job : jobs)
    if (readiness("job", job) != Readiness::slicing) job_finished(job);
}

std::pair<long long, QueueEntry> PrinterService::next(Printer& printer) {
  std::lock_guard lock(queue_mutex_);
  if (printer.state() == PrinterState::operational) bed_full_.erase(printer.id());  // declared clear
  if (auto started = start_first_ready(printer, printer.id())) return *started;
  if (auto started = start_first_ready(printer, profile_key(printer.config().profile))) return *started;
  throw Conflict("queue_empty",
                 "printer " + printer.id() + " has nothing ready in its queue or its profile's");
}

void PrinterService::auto_start(Printer& printer) {
  std::lock_guard lock(queue_mutex_);
  // Skips entries that cannot print any more; stops at the first that starts, or when the
  // printer cannot take one.
  for (int tries = 0; tries < 64 && printer.state() == PrinterState::operational; ++tries) {
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

void PrinterService::dispatch_profile(const std::string& profile) {
  std::lock_guard lock(queue_mutex_);
  for (auto& p : printers_) {
    if (p->config().profile != profile) continue;
    for (int tries = 0; tries < 64 && idle(*p) && bed_clear(*p); ++tries) {
      try {
        if (!start_first_ready(*p, profile_key(profile))) return;  // nothing ready for anyone
        break;
      } catch (const Conflict& e) {
        if (e.code() == "printer_busy") break;
      } catch (const DomainError&) {  // a gone entry, dropped: the next one
      } catch (const std::exception&) {
        return;
      }
    }
  }
}

void PrinterService::job_finished(const std::string& job_id) {
  std::lock_guard lock(queue_mutex_);
  const Readiness r = readiness("job", job_id);
  QueueStore queue(store_.db());
  for (const QueueEntry& e : queue.holding("job", job_id)) {
    if (r == Readiness::gone) {  // failed or cancelled: it will never print
      queue.remove(e.printer_id, e.id);
      queue_changed(e.printer_id);
      continue;
    }
    if (e.printer_id.rfind("profile/", 0) == 0) {
      dispatch_profile(e.printer_id.substr(8));
      continue;
    }
    // The user asked for it to print once sliced: it starts if the printer is free and nothing
    // ready is ahead of it (else it waits its turn like any other).
    Printer* printer = nullptr;
    for (auto& p : printers_)
      if (p->id() == e.printer_id) printer = p.get();
    if (!printer || printer->state() != PrinterState::operational || !bed_clear(*printer)) continue;
    bool ahead = false;
    for (const QueueEntry& other : queue.list(e.printer_id))
      if (other.position < e.position && readiness(other.kind, other.ref) == Readiness::ready) ahead = true;
    if (ahead) continue;
    try {
      start_first_ready(*printer, e.printer_id);
    } catch (const std::exception&) {  // busy after all, or gone: the queue says what is left
    }
  }
}

void PrinterService::remove_queued(Printer& printer, long long entry) {
  std::lock_guard lock(queue_mutex_);
  if (!QueueStore(store_.db()).remove(printer.id(), entry))
    throw NotFound("no entry " + std::to_string(entry) + " in the queue of " + printer.id());
  queue_changed(printer);
}

void PrinterService::remove_from_profile(const std::string& profile, long long entry) {
  std::lock_guard lock(queue_mutex_);
  if (!QueueStore(store_.db()).remove(profile_key(profile), entry))
    throw NotFound("no entry " + std::to_string(entry) + " in the queue of profile " + profile);
  queue_changed(profile_key(profile));
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

void PrinterService::queue_changed(const std::string& key) {
  if (queue_changed_) queue_changed_(key, entries(key));
}

}  // namespace salient::server
