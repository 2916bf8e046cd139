// Printer's calls from other threads: each checks the state under mutex_, then queues a command
// for the printer's thread or sets a request on the running link (see printer.hpp).
#include "server/printers/printer.hpp"

#include "protocol/gcode/command_code.hpp"
#include "protocol/link/printer_link.hpp"
#include "server/common/domain_error.hpp"
#include "server/printers/print_file.hpp"
#include "server/printers/sim_process.hpp"

namespace salient::server {
namespace {

using Clock = std::chrono::steady_clock;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string is(PrinterState state) {
  return "is " + std::string(to_string(state));
}

// Why a request that needs a connected, idle printer cannot go now.
std::string not_ready(PrinterState state, const std::string& error) {
  switch (state) {
    case PrinterState::disconnected:
      return "is not connected: POST …/connect first";
    case PrinterState::error:
      return "is not connected (" + error + "): POST …/connect to try again";
    case PrinterState::connecting:
      return "is still connecting";
    default:
      return is(state);
  }
}

}  // namespace

Printer::Printer(PrinterConfig config, Store& store, Hooks hooks)
    : config_(std::move(config)), store_(store), hooks_(std::move(hooks)) {
  last_ = PrintStore(store_.db()).latest(config_.id);
}

Printer::~Printer() {
  stop();
}

void Printer::start() {
  std::lock_guard lock(mutex_);
  if (config_.autoconnect) queue_.push(ConnectCommand{});
  thread_ = std::thread([this] { run(); });
  saver_.start();
}

void Printer::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !thread_.joinable()) return;
    stopping_ = true;
    if (link_ && busy_printing(state_)) link_->interrupt();
    if (connecting_) connecting_->interrupt();  // a silent board would hold the handshake for seconds
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  saver_.stop();  // after the thread, which asks it for writes
}

void Printer::notify(bool progress) const {
  if (hooks_.changed) hooks_.changed(*this, progress);
}

bool Printer::save_progress() {
  std::lock_guard write(save_mutex_);
  long long id = 0, confirmed = 0;
  PrintState state = PrintState::printing;
  PrintUsage usage;
  {
    std::lock_guard lock(mutex_);
    if (!current_) return true;
    id = current_->record.id, confirmed = current_->confirmed, usage = current_->usage();
    if (state_ == PrinterState::paused) state = PrintState::paused;
  }
  try {
    PrintStore(store_.db()).set_progress(id, state, confirmed, usage);  // only while not finished
    return true;
  } catch (const StoreError&) {
    return false;
  }
}

void Printer::conflict(const std::string& message) const {
  throw Conflict("printer_busy", "printer " + config_.id + " " + message);
}

PrinterState Printer::state() const {
  std::lock_guard lock(mutex_);
  return state_;
}

PrinterCounters Printer::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

PrinterStatus Printer::status() const {
  std::lock_guard lock(mutex_);
  return status_locked();
}

std::vector<PrinterStatus> Printer::state_changes_since(std::uint64_t& seq) const {
  std::lock_guard lock(mutex_);
  const std::uint64_t oldest = changes_end_ + 1 - changes_.size();  // changes_end_ + 1 when none
  std::vector<PrinterStatus> out;
  for (std::uint64_t i = std::max(seq + 1, oldest); i <= changes_end_; ++i)
    out.push_back(changes_[i - oldest]);
  seq = changes_end_;
  return out;
}

void Printer::enter(PrinterState state, const std::string& error) {
  if (state_ == state && error_ == error) return;
  state_ = state;
  error_ = error;
  changes_.push_back(status_locked());
  ++changes_end_;
  if (changes_.size() > kMaxStateChanges) changes_.pop_front();
}

PrinterStatus Printer::status_locked() const {
  PrinterStatus s;
  s.id = config_.id;
  s.kind = config_.kind;
  s.protocol = config_.protocol;
  s.profile = config_.profile;
  s.state = state_;
  s.error = error_, s.firmware = firmware_, s.device = device_;
  s.hotend = hotend_, s.bed = bed_;
  if (current_) {
    PrinterStatus::Running& p = s.print.emplace();
    p.record = current_->record;
    p.record.state = state_ == PrinterState::paused ? PrintState::paused : PrintState::printing;
    p.record.confirmed = current_->confirmed;
    p.record.total = current_->total;
    const PrintUsage usage = current_->usage();
    p.record.filament_mm = usage.filament_mm, p.record.paused_seconds = usage.paused_seconds;
    if (current_->extruded) p.z = current_->extruded->z_mm();
    p.elapsed = std::chrono::duration<double>(Clock::now() - current_->started).count();
    p.file_bytes = current_->file_bytes;
    p.filepos = p.file_bytes;
    if (const auto& program = current_->program; program && !program->empty()) {
      const auto next =
          std::min<std::size_t>(static_cast<std::size_t>(current_->confirmed), program->size() - 1);
      if (static_cast<std::size_t>(current_->confirmed) < program->size())
        p.filepos = std::min(p.file_bytes, (*program)[next].offset);
      p.layers = program->layers();  // 1 when the file marks no layer: then none is told
      if (p.layers > 1)
        p.layer = (*program)[next].layer + 1;
      else
        p.layers = 0;
    }
  }
  s.last_print = last_;
  return s;
}

void Printer::connect() {
  {
    std::lock_guard lock(mutex_);
    if (state_ != PrinterState::disconnected && state_ != PrinterState::error)
      conflict("is already " + std::string(to_string(state_)));
    queue_.push(ConnectCommand{});
  }
  wake_.notify_all();
}

void Printer::disconnect() {
  {
    std::lock_guard lock(mutex_);
    if (busy_printing(state_)) conflict(is(state_) + ": cancel the print first");
    if (state_ == PrinterState::disconnected) return;
    queue_.push(DisconnectCommand{});
  }
  wake_.notify_all();
}

long long Printer::print(const PrintRequest& request) {
  const long long id = start_print(request);
  notify(false);
  return id;
}

void Printer::refuse_unless_ready() const {
  if (state_ != PrinterState::operational || queue_.print_waiting())
    conflict(state_ == PrinterState::operational ? std::string("is starting a print")
                                                 : not_ready(state_, error_));
}

long long Printer::start_print(const PrintRequest& request) {
  {
    std::lock_guard lock(mutex_);
    refuse_unless_ready();
  }
  // Reading and counting a large file happens outside the lock that status requests take.
  Current c;
  const std::string gcode = store_.files().read(request.file_digest);
  std::shared_ptr<const protocol::Program> program = printable_program(request.filename, gcode, &config_);
  c.file_bytes = gcode.size();
  c.total = static_cast<long long>(program->size());
  c.program = program;
  std::lock_guard lock(mutex_);
  refuse_unless_ready();  // another request may have started one meanwhile
  c.record =
      PrintStore(store_.db())
          .create(config_.id, request.job_id, request.file_digest, request.filename, c.total, now_seconds());
  c.confirmed = static_cast<long long>(request.resume_from);
  c.started = Clock::now();
  c.extruded.emplace(*program);              // the program is held by c.program as long as c lives
  c.extruded->skip_to(request.resume_from);  // a resumed print counts what it pushes itself
  queue_.push(PrintCommand{request, c.record.id, std::move(program)});
  cancel_requested_ = pause_pending_ = false;
  current_ = c;
  enter(PrinterState::printing);
  wake_.notify_all();
  return c.record.id;
}

void Printer::pause() {
  {
    std::lock_guard lock(mutex_);
    if (state_ != PrinterState::printing || !link_) conflict(is(state_) + ": nothing to pause");
    if (print_streaming_)
      link_->pause();
    else
      pause_pending_ = true;
    if (current_) current_->paused_since = Clock::now();
    enter(PrinterState::paused);
  }
  notify(false);
  // Now, not with the next progress: a pause may confirm no further line (other nodes and a
  // restart read the print's state from the store).
  save_progress();
}

void Printer::resume() {
  {
    std::lock_guard lock(mutex_);
    if (state_ != PrinterState::paused || !link_) conflict(is(state_) + ": nothing to resume");
    if (print_streaming_)
      link_->resume();
    else
      pause_pending_ = false;
    if (current_ && current_->paused_since) {
      current_->paused_seconds +=
          std::chrono::duration<double>(Clock::now() - *current_->paused_since).count();
      current_->paused_since.reset();
    }
    enter(PrinterState::printing);
  }
  notify(false);
  save_progress();
}

void Printer::cancel() {
  {
    std::lock_guard lock(mutex_);
    // Finishing too: console lines sent after the file's last one (a heating wait, a long dwell)
    // may hold the link, and a cancel is the way out short of an emergency stop.
    const bool finishing = state_ == PrinterState::finishing && print_streaming_;
    if ((state_ != PrinterState::printing && state_ != PrinterState::paused && !finishing) || !link_)
      conflict(is(state_) + ": nothing to cancel");
    if (print_streaming_) {
      link_->cancel();
      cancel_requested_ = true;
      enter(PrinterState::cancelling);
    } else {
      drop_waiting_print();
    }
  }
  notify(false);
}

PrintUsage Printer::Current::usage() const {
  PrintUsage u{extruded ? extruded->extruded_mm() : 0, paused_seconds};
  if (paused_since) u.paused_seconds += std::chrono::duration<double>(Clock::now() - *paused_since).count();
  return u;
}

void Printer::drop_waiting_print() {
  queue_.take_print();
  pause_pending_ = false;
  if (!current_) return enter(PrinterState::operational);
  enter(PrinterState::cancelling);  // as a streamed cancel goes: clients count a cancel by it
  PrintRecord record = current_->record;
  record.state = PrintState::cancelled, record.confirmed = current_->confirmed;
  record.reason = "cancelled before it began";
  try {
    PrintStore(store_.db())
        .finish(record.id, record.state, record.confirmed, record.reason, now_seconds(), current_->usage());
    if (auto stored = PrintStore(store_.db()).get(record.id)) record = *stored;
  } catch (const StoreError&) {  // a full disk: the outcome is kept in memory
  }
  last_ = record;
  current_.reset();
  enter(PrinterState::operational);
}

void Printer::emergency_stop() {
  {
    std::lock_guard lock(mutex_);
    if (!link_) conflict(not_ready(state_, error_));
    // At once into whatever the link is streaming (a print, or console commands such as a long
    // G28); between them, the thread sends it within its next 100 ms.
    if (busy_printing(state_) || commands_running_)
      link_->emergency_stop();
    else
      queue_.push(EmergencyStopCommand{});
  }
  wake_.notify_all();
}

void Printer::command(const std::vector<std::string>& commands, bool force) {
  {
    std::lock_guard lock(mutex_);
    if (state_ == PrinterState::printing && !force)
      for (const std::string& c : commands)
        if (const auto code = protocol::command_code(c); code && protocol::moves_or_homes(*code))
          throw Conflict("printer_printing",
                         "printer " + config_.id + " is printing: " + code->text +
                             " moves or homes the print head and would spoil the print; pause the print "
                             "first, or send it anyway with \"force\": true (salient send --force)");
    const bool in_print = state_ == PrinterState::printing || state_ == PrinterState::paused;
    if (in_print && print_streaming_) {  // into the stream, as OctoPrint does (a temperature, a flow rate)
      if (!link_->send(commands)) conflict(is(state_) + ": this printer takes commands between prints only");
      return;
    }
    // A print waiting to begin (behind other commands) lets these go before it: they are for now.
    if (state_ != PrinterState::operational && !in_print)
      conflict(busy_printing(state_) ? is(state_) + ": commands go between prints"
                                     : not_ready(state_, error_));
    if (queue_.console_full())
      throw TooBusy("busy", "printer " + config_.id + " has 16 command batches waiting: try again shortly",
                    2);
    queue_.push(ConsoleCommand{commands});
  }
  wake_.notify_all();
}

}  // namespace salient::server
