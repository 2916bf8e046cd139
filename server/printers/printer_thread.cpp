// What a Printer's own thread does: takes the next command from the queue, opens and closes the
// link, streams prints and console commands, listens between them, and turns what the link
// reports into the status and the database (see printer.hpp for the threading rule).
#include <algorithm>

#include "protocol/link/printer_link.hpp"
#include "server/printers/printer.hpp"
#include "server/printers/printer_connection.hpp"

namespace salient::server {
namespace {

using Clock = std::chrono::steady_clock;
using protocol::LinkError;
using protocol::LinkEvent;
using protocol::PrintEnd;
using protocol::PrintResult;

const std::string kHalted = "emergency stop (M112): the firmware halted; connect again to go on";

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

}  // namespace

void Printer::set_state(PrinterState state, const std::string& error) {
  {
    std::lock_guard lock(mutex_);
    enter(state, error);
  }
  notify(false);
}

void Printer::run() {
  Throttle throttle;
  const EventFn on_event = [this, &throttle](const LinkEvent& e) { handle_event(e, throttle); };
  Replug replug;
  for (;;) {
    std::unique_lock lock(mutex_);
    if (!link_) {
      const auto ready = [&] { return stopping_ || queue_.connect_waiting(); };
      if (!replug_)
        wake_.wait(lock, ready);
      else if (!wake_.wait_for(lock, kReplugPoll, ready)) {
        lock.unlock();
        poll_replug(replug);
        continue;
      }
    }
    if (stopping_) break;
    // A print paused before it began stays in the queue until resumed: nothing of it goes.
    std::optional<PrinterCommand> next = queue_.take(link_ != nullptr, pause_pending_);
    commands_running_ = next && std::holds_alternative<ConsoleCommand>(*next);
    // From here requests go to the link, which keeps one made before the stream begins.
    if (next && std::holds_alternative<PrintCommand>(*next)) print_streaming_ = true;
    lock.unlock();
    if (!next) {
      try {
        link_->idle(std::chrono::milliseconds(100), on_event);
      } catch (const LinkError& e) {
        close_link(PrinterState::error, e.what());
      }
      continue;
    }
    std::visit(Overloaded{[&](const ConnectCommand&) {
                            replug_ = config_.kind == PrinterKind::serial;
                            replug = Replug{};
                            open_link();
                          },
                          [&](const DisconnectCommand&) {
                            replug_ = false;
                            close_link(PrinterState::disconnected, "");
                          },
                          [&](const EmergencyStopCommand&) {
                            replug_ = false;  // a halted board waits for a person
                            try {
                              link_->halt_now();
                            } catch (const LinkError&) {
                            }
                            close_link(PrinterState::error, kHalted);
                          },
                          [&](const PrintCommand& p) { run_print(p, on_event); },
                          [&](const ConsoleCommand& c) { run_console(c.lines, on_event); }},
               *next);
  }
  close_link(PrinterState::disconnected, "");
}

void Printer::run_console(const std::vector<std::string>& lines, const EventFn& on_event) {
  try {
    const PrintResult r = link_->print(
        std::make_shared<const protocol::Program>(protocol::Program::from_lines(lines)), on_event);
    {
      std::lock_guard done(mutex_);
      commands_running_ = false;
    }
    if (r.disconnected)
      close_link(PrinterState::error, r.reason);
    else if (r.end == PrintEnd::failed) {
      replug_ = false;  // the firmware failed (halted, a kill): a person looks first, not a reconnect
      close_link(PrinterState::error, r.reason == "emergency stop" ? kHalted : r.reason);
    }
  } catch (const LinkError& e) {
    {
      std::lock_guard done(mutex_);
      commands_running_ = false;
    }
    close_link(PrinterState::error, e.what());
  }
}

void Printer::open_link() {
  set_state(PrinterState::connecting);
  try {
    PrinterConnection c = open_printer_connection(
        config_, {[this] { return hooks_.terminal_wanted && hooks_.terminal_wanted(*this); },
                  [this](bool sent, std::string_view line) {
                    if (hooks_.terminal) hooks_.terminal(*this, sent, line);
                  }});
    {
      std::lock_guard lock(mutex_);
      if (stopping_) c.link->interrupt();
      connecting_ = c.link.get();
    }
    protocol::FirmwareInfo firmware;
    try {
      firmware = c.link->handshake();
    } catch (...) {
      std::lock_guard lock(mutex_);
      connecting_ = nullptr;
      throw;
    }
    {
      std::lock_guard lock(mutex_);
      connecting_ = nullptr;
      sim_ = std::move(c.sim);
      link_ = std::move(c.link);
      firmware_ = firmware.name;
      device_ = c.device;
      enter(PrinterState::operational);
    }
    notify(false);
  } catch (const std::exception& e) {
    {
      std::lock_guard lock(mutex_);
      queue_.clear();  // a disconnect asked for during the handshake is moot now
    }
    set_state(PrinterState::error, std::string("cannot connect: ") + e.what());
  }
}

void Printer::close_link(PrinterState state, const std::string& error) {
  std::unique_ptr<protocol::PrinterLink> link;
  std::unique_ptr<SimProcess> sim;
  {
    std::lock_guard lock(mutex_);
    link = std::move(link_);
    sim = std::move(sim_);
    // Requests were for this connection: none of them is carried over to the next one.
    queue_.clear();
    print_streaming_ = pause_pending_ = false;
    const bool had = link != nullptr || state_ != state;
    device_.clear();
    hotend_ = bed_ = Temperature{};
    enter(state, error);
    if (!had) return;
  }
  link.reset();
  sim.reset();
  notify(false);
}

void Printer::handle_event(const LinkEvent& e, Throttle& throttle) {
  using Kind = LinkEvent::Kind;
  bool tell = false, save = false, finishing = false;
  {
    std::lock_guard lock(mutex_);
    if (e.kind == Kind::temperatures) {
      if (e.hotend) hotend_.actual = e.hotend;
      if (e.hotend_target) hotend_.target = e.hotend_target;
      if (e.bed) bed_.actual = e.bed;
      if (e.bed_target) bed_.target = e.bed_target;
      tell = true;
    } else if (e.kind == Kind::progress && current_ && print_streaming_) {  // not a console batch's
      current_->confirmed = static_cast<long long>(e.done);
      current_->extruded->advance_to(e.done);
      tell = true;
      // The last command is confirmed: the file is done, what is left is recording the print.
      if (state_ == PrinterState::printing && current_->confirmed >= current_->total) {
        enter(PrinterState::finishing);
        finishing = true;
      }
      // Saved at most every 20 ms: a kill -9 repeats at most that much of the print on resume.
      if (Clock::now() - throttle.last_save >= std::chrono::milliseconds(20))
        save = true, throttle.last_save = Clock::now();
    }
  }
  if (finishing) notify(false);  // a change of state: never throttled
  // Told at most 10 times a second, saved at most 50 times: a print acknowledges thousands of lines a second.
  if (tell && !finishing && Clock::now() - throttle.last_notify >= std::chrono::milliseconds(100)) {
    throttle.last_notify = Clock::now();
    notify(true);
  }
  // Written on the saver's thread: neither a full disk nor a frozen database holds up the print.
  if (save) saver_.request();
}

PrintState Printer::print_outcome(const PrintResult& result, bool interrupted, bool cancelled) const {
  switch (result.end) {
    case PrintEnd::finished:
      return PrintState::finished;
    case PrintEnd::cancelled:
      return interrupted ? PrintState::interrupted : PrintState::cancelled;
    case PrintEnd::failed:
      // A cancel that had to halt the firmware, or whose printer went silent, is still a cancel.
      return cancelled || result.halted           ? PrintState::cancelled
             : interrupted || result.disconnected ? PrintState::interrupted
                                                  : PrintState::failed;
  }
  return PrintState::failed;
}

void Printer::run_print(const PrintCommand& print, const EventFn& on_event) {
  const PrintRequest& request = print.request;
  PrintResult result;
  PrintState state = PrintState::failed;
  bool streamed = false;  // the link ran it (not an exception before)
  try {
    result = link_->print(print.program, on_event, request.resume_from);
    streamed = true;
    bool interrupted = false, cancelled = false;
    {
      std::lock_guard lock(mutex_);
      interrupted = stopping_;
      cancelled = cancel_requested_;
    }
    state = print_outcome(result, interrupted, cancelled);
    if (interrupted && result.reason.empty()) result.reason = "the daemon stopped during the print";
  } catch (const std::exception& e) {
    result.reason = e.what();
  }
  // A print that ended well is finishing until it is recorded (when the link did not confirm
  // its last command through a progress event, it enters the phase here).
  if (state == PrintState::finished) {
    bool entered = false;
    {
      std::lock_guard lock(mutex_);
      if (state_ == PrinterState::printing) enter(PrinterState::finishing), entered = true;
    }
    if (entered) notify(false);
  }
  const std::optional<std::string> reason =
      result.reason.empty() ? std::nullopt : std::optional<std::string>(result.reason);
  PrintUsage usage;
  {
    std::lock_guard lock(mutex_);
    if (current_) {  // the link's count is the last word on what was confirmed
      current_->extruded->advance_to(result.confirmed);
      usage = current_->usage();
    }
  }
  PrintStore prints(store_.db());
  std::optional<PrintRecord> record;
  try {
    prints.finish(print.print_id, state, static_cast<long long>(result.confirmed), reason, now_seconds(),
                  usage);
    record = prints.get(print.print_id);
  } catch (const StoreError&) {  // a full disk: the outcome is kept in memory; the row says "printing"
  }
  {
    std::lock_guard lock(mutex_);
    if (!record && current_) {
      record = current_->record;
      record->filament_mm = usage.filament_mm, record->paused_seconds = usage.paused_seconds;
      record->state = state, record->confirmed = static_cast<long long>(result.confirmed),
      record->reason = reason;
    }
    last_ = record;
    current_.reset();
    print_streaming_ = false;
    // Console lines sent into the print as it ended: they go now, as commands between prints.
    if (!result.unsent.empty()) queue_.push(ConsoleCommand{std::move(result.unsent)});
    counters_.lines_sent +=
        static_cast<long long>(result.confirmed - std::min(result.confirmed, request.resume_from));
    counters_.lines_resent += static_cast<long long>(result.lines_resent);
    if (state == PrintState::finished) ++counters_.prints_finished;
    if (state == PrintState::failed || state == PrintState::interrupted) ++counters_.prints_failed;
    enter(PrinterState::operational);
  }
  if (result.disconnected)
    return close_link(PrinterState::error, "link lost during the print: " + result.reason);
  if (streamed && result.end == PrintEnd::failed) {
    replug_ = false;  // the firmware failed (halted, thermal runaway): a person looks first, not a reconnect
    return close_link(PrinterState::error, result.reason.empty() ? "the print failed" : result.reason);
  }
  notify(false);
}

}  // namespace salient::server
