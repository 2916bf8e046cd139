#include "server/printers/printer.hpp"

#include <nlohmann/json.hpp>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/marlin/resume_prelude.hpp"
#include "protocol/serial/marlin_link.hpp"
#include "server/http/json_text.hpp"
#include "server/http/router.hpp"
#include "server/printers/sim_process.hpp"
#include "server/printers/terminal_tap.hpp"

namespace salient::server {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
namespace serial = protocol::serial;
namespace marlin = protocol::marlin;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

json optional_number(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

json record_json(const PrintRecord& p) {
  return {{"id", p.id},
          {"job", p.job_id ? json(*p.job_id) : json(nullptr)},
          {"file", p.filename},
          {"state", p.state},
          {"confirmed", p.confirmed},
          {"total", p.total},
          {"progress", p.total > 0 ? double(p.confirmed) / double(p.total) : 0.0},
          {"reason", p.reason ? json(*p.reason) : json(nullptr)},
          {"started_at", p.started_at},
          {"finished_at", p.finished_at ? json(*p.finished_at) : json(nullptr)},
          // What a restart or a pulled cable leaves: where `POST …/print {"resume": id}` goes on from.
          {"resumable", p.state != "finished" && p.state != "cancelled" && p.state != "printing" &&
                            p.state != "paused" && p.confirmed > 0 && p.confirmed < p.total}};
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t nl = text.find('\n', start);
    if (nl == std::string::npos) nl = text.size();
    std::string line = text.substr(start, nl - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(std::move(line));
    start = nl + 1;
  }
  return lines;
}

[[noreturn]] void conflict(const std::string& id, const std::string& message) {
  throw ApiError(409, "printer_busy", "printer " + id + " " + message);
}

// Why a request that needs a connected, idle printer cannot go now.
std::string not_ready(const std::string& state, const std::string& error) {
  if (state == "disconnected") return "is not connected: POST …/connect first";
  if (state == "error") return "is not connected (" + error + "): POST …/connect to try again";
  if (state == "connecting") return "is still connecting";
  return "is " + state;
}

}  // namespace

long long check_printable(const std::string& name, const std::string& gcode) {
  const std::vector<std::string> lines = split_lines(gcode);
  // A line the firmware cannot take would stall the print halfway: refused before it starts.
  if (auto bad = protocol::marlin::find_unsendable(lines))
    throw ApiError(422, "not_gcode",
                   name + " line " + std::to_string(bad->line) + " cannot be sent: " + bad->why);
  long long commands = 0;
  for (const std::string& line : lines)
    if (!protocol::marlin::strip_comment(line).empty()) ++commands;
  if (commands == 0)
    throw ApiError(422, "no_commands", name + " holds no G-code commands (only comments or blank lines)");
  return commands;
}

Printer::Printer(PrinterConfig config, Store& store, Hooks hooks)
    : config_(std::move(config)), store_(store), hooks_(std::move(hooks)) {
  last_ = PrintStore(store_.db()).latest(config_.id);
}

Printer::~Printer() {
  stop();
}

void Printer::start() {
  std::lock_guard lock(mutex_);
  connect_wanted_ = config_.autoconnect;
  thread_ = std::thread([this] { run(); });
}

void Printer::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !thread_.joinable()) return;
    stopping_ = true;
    if (link_ && (state_ == "printing" || state_ == "paused" || state_ == "cancelling")) link_->interrupt();
    if (connecting_) connecting_->interrupt();  // a silent board would hold the handshake for seconds
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Printer::notify(bool progress) const {
  if (hooks_.changed) hooks_.changed(*this, progress);
}

void Printer::set_state(const std::string& state, const std::string& error) {
  {
    std::lock_guard lock(mutex_);
    state_ = state;
    error_ = error;
  }
  notify(false);
}

std::string Printer::state() const {
  std::lock_guard lock(mutex_);
  return state_;
}

PrinterCounters Printer::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::string Printer::status_json() const {
  std::lock_guard lock(mutex_);
  json print = nullptr;
  if (current_) {
    print = record_json(current_->record);
    print["state"] = state_ == "paused" ? "paused" : "printing";
    print["confirmed"] = current_->confirmed;
    print["total"] = current_->total;
    const double fraction = current_->total > 0 ? double(current_->confirmed) / double(current_->total) : 0.0;
    const double elapsed = std::chrono::duration<double>(Clock::now() - current_->started).count();
    print["progress"] = fraction;
    print["elapsed"] = elapsed;
    print["eta"] = fraction > 0.01 ? json(elapsed * (1 - fraction) / fraction) : json(nullptr);
  }
  return json_text(
      json{{"id", config_.id},
           {"kind", config_.kind},
           {"protocol", config_.protocol},
           {"profile", config_.profile},
           {"state", state_},
           {"error", error_.empty() ? json(nullptr) : json(error_)},
           {"firmware", firmware_.empty() ? json(nullptr) : json(firmware_)},
           {"device", device_.empty() ? json(nullptr) : json(device_)},
           {"temperatures",
            {{"hotend", {{"actual", optional_number(hotend_)}, {"target", optional_number(hotend_target_)}}},
             {"bed", {{"actual", optional_number(bed_)}, {"target", optional_number(bed_target_)}}}}},
           {"print", print},
           {"last_print", last_ ? record_json(*last_) : json(nullptr)}});
}

void Printer::connect() {
  {
    std::lock_guard lock(mutex_);
    if (state_ != "disconnected" && state_ != "error") conflict(config_.id, "is already " + state_);
    connect_wanted_ = true;
  }
  wake_.notify_all();
}

void Printer::disconnect() {
  {
    std::lock_guard lock(mutex_);
    if (state_ == "printing" || state_ == "paused" || state_ == "cancelling")
      conflict(config_.id, "is " + state_ + ": cancel the print first");
    if (state_ == "disconnected") return;
    disconnect_wanted_ = true;
    connect_wanted_ = false;
  }
  wake_.notify_all();
}

long long Printer::print(const PrintRequest& request) {
  const long long id = start_print(request);
  notify(false);
  return id;
}

long long Printer::start_print(const PrintRequest& request) {
  const auto refuse_unless_ready = [this] {
    if (state_ != "operational" || print_wanted_)
      conflict(config_.id,
               state_ == "operational" ? std::string("is starting a print") : not_ready(state_, error_));
  };
  {
    std::lock_guard lock(mutex_);
    refuse_unless_ready();
  }
  // Reading and counting a large file happens outside the lock that status requests take.
  Current c;
  c.total = check_printable(request.filename, store_.files().read(request.file_digest));
  std::lock_guard lock(mutex_);
  refuse_unless_ready();  // another request may have started one meanwhile
  c.record =
      PrintStore(store_.db())
          .create(config_.id, request.job_id, request.file_digest, request.filename, c.total, now_seconds());
  c.confirmed = static_cast<long long>(request.resume_from);
  c.started = Clock::now();
  print_wanted_ = request;
  print_wanted_id_ = c.record.id;
  cancel_requested_ = false;
  current_ = c;
  state_ = "printing";
  error_.clear();
  wake_.notify_all();
  return c.record.id;
}

void Printer::pause() {
  {
    std::lock_guard lock(mutex_);
    if (state_ != "printing" || !link_) conflict(config_.id, "is " + state_ + ": nothing to pause");
    link_->pause();
    state_ = "paused";
  }
  notify(false);
}

void Printer::resume() {
  {
    std::lock_guard lock(mutex_);
    if (state_ != "paused" || !link_) conflict(config_.id, "is " + state_ + ": nothing to resume");
    link_->resume();
    state_ = "printing";
  }
  notify(false);
}

void Printer::cancel() {
  {
    std::lock_guard lock(mutex_);
    if ((state_ != "printing" && state_ != "paused") || !link_)
      conflict(config_.id, "is " + state_ + ": nothing to cancel");
    link_->cancel();
    cancel_requested_ = true;
    state_ = "cancelling";
  }
  notify(false);
}

void Printer::emergency_stop() {
  {
    std::lock_guard lock(mutex_);
    if (!link_) conflict(config_.id, not_ready(state_, error_));
    // At once into whatever the link is streaming (a print, or console commands such as a long
    // G28); between them, the thread sends it within its next 100 ms.
    if (state_ == "printing" || state_ == "paused" || state_ == "cancelling" || commands_running_)
      link_->emergency_stop();
    else
      estop_wanted_ = true;
  }
  wake_.notify_all();
}

void Printer::command(const std::vector<std::string>& commands) {
  {
    std::lock_guard lock(mutex_);
    if (state_ != "operational" || print_wanted_)
      conflict(config_.id, state_ == "printing" || state_ == "paused"
                               ? "is " + state_ + ": commands go between prints"
                               : not_ready(state_, error_));
    if (commands_wanted_.size() >= 16)
      throw ApiError(429, "busy",
                     "printer " + config_.id + " has 16 command batches waiting: try again shortly")
          .with_header("Retry-After", "2");
    commands_wanted_.push_back(commands);
  }
  wake_.notify_all();
}

void Printer::run() {
  Throttle throttle;
  const auto on_event = [this, &throttle](const marlin::SessionEvent& e) { handle_event(e, throttle); };

  for (;;) {
    std::unique_lock lock(mutex_);
    if (!link_) wake_.wait(lock, [&] { return stopping_ || connect_wanted_; });
    if (stopping_) break;
    if (!link_) {
      connect_wanted_ = false;
      lock.unlock();
      open_link();
      continue;
    }
    if (disconnect_wanted_) {
      disconnect_wanted_ = false;
      lock.unlock();
      close_link("disconnected", "");
      continue;
    }
    if (estop_wanted_) {
      estop_wanted_ = false;
      lock.unlock();
      try {
        link_->send_now("M112");
      } catch (const serial::LinkError&) {
      }
      close_link("error", "emergency stop (M112): the firmware halted; connect again to go on");
      continue;
    }
    if (print_wanted_) {
      const PrintRequest request = *print_wanted_;
      print_wanted_.reset();
      const long long id = print_wanted_id_;
      lock.unlock();
      run_print(request, id, on_event);
      continue;
    }
    connect_wanted_ = false;
    std::vector<std::string> commands;
    if (!commands_wanted_.empty()) {
      commands = std::move(commands_wanted_.front());
      commands_wanted_.erase(commands_wanted_.begin());
    }
    commands_running_ = !commands.empty();
    lock.unlock();
    try {
      if (!commands.empty()) {
        const serial::PrintResult r = link_->print(commands, on_event);
        {
          std::lock_guard done(mutex_);
          commands_running_ = false;
        }
        if (r.disconnected)
          close_link("error", r.reason);
        else if (r.state == marlin::SessionState::failed)
          close_link("error", r.reason == "emergency stop"
                                  ? "emergency stop (M112): the firmware halted; connect again to go on"
                                  : r.reason);
      } else {
        link_->idle(std::chrono::milliseconds(100), on_event);
      }
    } catch (const serial::LinkError& e) {
      {
        std::lock_guard done(mutex_);
        commands_running_ = false;
      }
      close_link("error", e.what());
    }
  }
  close_link("disconnected", "");
}

void Printer::open_link() {
  set_state("connecting");
  std::unique_ptr<SimProcess> sim;
  try {
    std::string device = config_.port;
    if (config_.kind == "sim") {
      sim = std::make_unique<SimProcess>(find_sim_program(), split_args(config_.sim_args));
      device = sim->device();
    }
    std::unique_ptr<serial::Transport> transport =
        config_.kind == "tcp" ? serial::open_tcp(config_.port) : serial::open_serial({device, config_.baud});
    auto tap = std::make_unique<TerminalTap>(
        std::move(transport), [this] { return hooks_.terminal_wanted && hooks_.terminal_wanted(); },
        [this](bool sent, std::string_view line) {
          if (hooks_.terminal) hooks_.terminal(*this, sent, line);
        });
    auto link = std::make_unique<serial::MarlinLink>(std::move(tap));
    {
      std::lock_guard lock(mutex_);
      if (stopping_) link->interrupt();
      connecting_ = link.get();
    }
    serial::FirmwareInfo firmware;
    try {
      firmware = link->handshake();
    } catch (...) {
      std::lock_guard lock(mutex_);
      connecting_ = nullptr;
      throw;
    }
    {
      std::lock_guard lock(mutex_);
      connecting_ = nullptr;
      sim_ = std::move(sim);
      link_ = std::move(link);
      firmware_ = firmware.name;
      device_ = device;
      state_ = "operational";
      error_.clear();
    }
    notify(false);
  } catch (const std::exception& e) {
    set_state("error", std::string("cannot connect: ") + e.what());
  }
}

void Printer::close_link(const std::string& state, const std::string& error) {
  std::unique_ptr<serial::MarlinLink> link;
  std::unique_ptr<SimProcess> sim;
  {
    std::lock_guard lock(mutex_);
    link = std::move(link_);
    sim = std::move(sim_);
    // Requests were for this connection: none of them is carried over to the next one.
    estop_wanted_ = disconnect_wanted_ = false;
    commands_wanted_.clear();
    const bool had = link != nullptr || state_ != state;
    state_ = state;
    error_ = error;
    device_.clear();
    hotend_ = hotend_target_ = bed_ = bed_target_ = std::nullopt;
    if (!had) return;
  }
  link.reset();
  sim.reset();
  notify(false);
}

void Printer::handle_event(const marlin::SessionEvent& e, Throttle& throttle) {
  using Kind = marlin::SessionEvent::Kind;
  bool tell = false, save = false;
  long long print_id = 0, confirmed = 0;
  std::string state;
  {
    std::lock_guard lock(mutex_);
    if (e.kind == Kind::temperatures) {
      const auto& t = e.temperatures;
      if (t.hotend) hotend_ = t.hotend;
      if (t.hotend_target) hotend_target_ = t.hotend_target;
      if (t.bed) bed_ = t.bed;
      if (t.bed_target) bed_target_ = t.bed_target;
      tell = true;
    } else if (e.kind == Kind::acknowledged && current_) {
      current_->confirmed = e.line;
      tell = true;
      // Saved at most every 20 ms: a kill -9 repeats at most that much of the print on resume.
      if (Clock::now() - throttle.last_save >= std::chrono::milliseconds(20)) {
        save = true, throttle.last_save = Clock::now();
        print_id = current_->record.id, confirmed = current_->confirmed, state = state_;
      }
    }
  }
  // Told at most 10 times a second, saved at most 50 times: a print acknowledges thousands of lines a second.
  if (tell && Clock::now() - throttle.last_notify >= std::chrono::milliseconds(100)) {
    throttle.last_notify = Clock::now();
    notify(true);
  }
  if (save && Clock::now() >= throttle.saves_paused_until) {
    try {
      PrintStore(store_.db()).set_progress(print_id, state == "paused" ? "paused" : "printing", confirmed);
    } catch (const StoreError&) {
      // A full disk must not stop the print: progress writes pause, and are tried again later.
      throttle.saves_paused_until = Clock::now() + std::chrono::seconds(5);
    }
  }
}

void Printer::run_print(const PrintRequest& request, long long print_id,
                        const std::function<void(const marlin::SessionEvent&)>& on_event) {
  serial::PrintResult result;
  std::string state = "failed";
  bool interrupted = false;
  try {
    const std::vector<std::string> gcode = split_lines(store_.files().read(request.file_digest));
    const std::vector<std::string> prelude = request.resume_from > 0
                                                 ? marlin::resume_prelude(gcode, request.resume_from)
                                                 : std::vector<std::string>{};
    result = link_->print(gcode, on_event, request.resume_from, prelude);
    bool cancelled = false;
    {
      std::lock_guard lock(mutex_);
      interrupted = stopping_;
      cancelled = cancel_requested_;
    }
    switch (result.state) {
      case marlin::SessionState::finished:
        state = "finished";
        break;
      case marlin::SessionState::cancelled:
        state = interrupted ? "interrupted" : "cancelled";
        break;
      default:  // failed: a cancel that had to halt the firmware, or whose printer went silent, is still a
                // cancel
        state = cancelled || result.halted           ? "cancelled"
                : interrupted || result.disconnected ? "interrupted"
                                                     : "failed";
        break;
    }
    if (interrupted && result.reason.empty()) result.reason = "the daemon stopped during the print";
  } catch (const std::exception& e) {
    result.reason = e.what();
  }
  const std::optional<std::string> reason =
      result.reason.empty() ? std::nullopt : std::optional<std::string>(result.reason);
  PrintStore prints(store_.db());
  std::optional<PrintRecord> record;
  try {
    prints.finish(print_id, state, static_cast<long long>(result.confirmed), reason, now_seconds());
    record = prints.get(print_id);
  } catch (const StoreError&) {  // a full disk: the outcome is kept in memory; the row says "printing"
  }
  {
    std::lock_guard lock(mutex_);
    if (!record && current_) {
      record = current_->record;
      record->state = state, record->confirmed = static_cast<long long>(result.confirmed),
      record->reason = reason;
    }
    last_ = record;
    current_.reset();
    counters_.lines_sent +=
        static_cast<long long>(result.confirmed - std::min(result.confirmed, request.resume_from));
    counters_.lines_resent += static_cast<long long>(result.lines_resent);
    if (state == "finished") ++counters_.prints_finished;
    if (state == "failed" || state == "interrupted") ++counters_.prints_failed;
    state_ = "operational";
  }
  if (result.disconnected) return close_link("error", "link lost during the print: " + result.reason);
  if (result.state == marlin::SessionState::failed)
    return close_link("error", result.reason.empty() ? "the print failed" : result.reason);
  notify(false);
}

}  // namespace salient::server
