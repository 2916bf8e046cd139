#include "server/printers/printer_service.hpp"

#include <chrono>
#include <nlohmann/json.hpp>

#include "server/common/domain_error.hpp"
#include "server/store/farm_store.hpp"
#include "server/store/job_store.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

PrinterService::PrinterService(const DaemonConfig& config, Store& store, PrinterEvents events)
    : store_(store), queue_changed_(std::move(events.queue_changed)) {
  // Prints a previous run left unfinished: interrupted, before any printer reads its last print.
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  if (store_.database_url().dialect == Dialect::postgresql) {
    std::vector<std::string> own;
    for (const PrinterConfig& p : config.printers) own.push_back(p.id);
    FarmStore(store_.db()).interrupt_own(own, now);
  } else {
    PrintStore(store_.db()).mark_interrupted(now);
  }
  for (const PrinterConfig& p : config.printers) temperatures_[p.id] = std::make_unique<TemperatureHistory>();
  // Every change a printer reports (its temperatures among them) is a chance to sample them.
  events.changed = [this, publish = std::move(events.changed)](const Printer& printer, bool progress) {
    TemperatureHistory& history = *temperatures_.at(printer.id());
    const double t =
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    if (history.due(t)) {
      const PrinterStatus s = printer.status();
      history.add({t, s.hotend, s.bed});
    }
    if (publish) publish(printer, progress);
    if (!progress && printer.config().auto_start) auto_start(get(printer.id()));
  };
  for (const PrinterConfig& p : config.printers) {
    printers_.push_back(std::make_unique<Printer>(p, store_, static_cast<const Printer::Hooks&>(events)));
  }
}

const TemperatureHistory& PrinterService::temperatures(const std::string& id) const {
  const auto it = temperatures_.find(id);
  if (it == temperatures_.end()) throw NotFound("no printer '" + id + "'");
  return *it->second;
}

PrinterService::~PrinterService() {
  stop();
}

void PrinterService::start() {
  for (auto& p : printers_) p->start();
}

void PrinterService::stop() {
  for (auto& p : printers_) p->stop();
}

Printer& PrinterService::get(const std::string& id) {
  for (auto& p : printers_)
    if (p->id() == id) return *p;
  throw NotFound("no printer '" + id + "'");
}

Printer* PrinterService::find(const std::string& id) {
  for (auto& p : printers_)
    if (p->id() == id) return p.get();
  return nullptr;
}

long long PrinterService::print_job(Printer& printer, const std::string& job_id) {
  const auto job = JobStore(store_.db()).get(job_id);
  if (!job) throw NotFound("no job " + job_id);
  if (job->state != JobState::done || !job->result)
    throw Conflict("not_ready",
                   "job " + job_id + " is " + std::string(to_string(job->state)) + ": nothing to print");
  const nlohmann::json result = nlohmann::json::parse(*job->result);
  const std::string stem = job->filename.substr(0, job->filename.find_last_of('.'));
  return occupied(printer,
                  printer.print({job_id, result.at("gcode").get<std::string>(), stem + ".gcode", 0}));
}

long long PrinterService::print_file(Printer& printer, const std::string& name) {
  const auto file = PrintStore(store_.db()).file(name);
  if (!file) throw NotFound("no file '" + name + "' (upload it to /api/files/local)");
  return occupied(printer, printer.print({std::nullopt, file->digest, file->name, 0}));
}

long long PrinterService::resume(Printer& printer, long long print_id) {
  const auto p = PrintStore(store_.db()).get(print_id);
  if (!p || p->printer_id != printer.id())
    throw NotFound("no print " + std::to_string(print_id) + " on " + printer.id());
  if (p->state == PrintState::finished || running(p->state) || p->confirmed >= p->total)
    throw Conflict("not_resumable", "print " + std::to_string(print_id) + " is " +
                                        std::string(to_string(p->state)) + ": nothing to resume");
  return occupied(printer, printer.print({p->job_id, p->file_digest, p->filename,
                                          static_cast<std::size_t>(p->confirmed)}));
}

}  // namespace salient::server
