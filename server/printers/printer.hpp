// Printer: one attached printer and the thread that owns its link. The thread connects (starting
// salient-sim first for kind "sim"), listens between prints, runs prints and console commands,
// and writes each print's progress (the last acknowledged command) to the database as it goes.
// Requests from HTTP threads are checked against the state (409 when they make no sense now) and
// handed over; pause, resume, cancel and emergency stop reach a running print at once.
//
// States: disconnected → connecting → operational ⇄ printing ⇄ paused; error after a failure
// (link lost, firmware halted, emergency stop) until the next connect.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/config/daemon_config.hpp"
#include "server/store/print_store.hpp"
#include "server/store/store.hpp"

namespace salient::protocol::serial {
class MarlinLink;
}
namespace salient::protocol::marlin {
struct SessionEvent;
}

namespace salient::server {

class SimProcess;

// The number of commands in `gcode`; ApiError 422 when it has none, or a line that cannot be
// sent (too long, binary, not ASCII), named with its line number.
long long check_printable(const std::string& name, const std::string& gcode);

struct PrintRequest {
  std::optional<std::string> job_id;
  std::string file_digest, filename;
  std::size_t resume_from = 0;  // commands already done (a resumed print)
};

struct PrinterCounters {
  long long lines_sent = 0, lines_resent = 0, prints_finished = 0, prints_failed = 0;
};

class Printer {
 public:
  struct Hooks {
    std::function<void(const Printer&, bool progress)> changed;  // state (false) or progress (true)
    std::function<bool()> terminal_wanted;                       // someone watches terminal/{id}
    std::function<void(const Printer&, bool sent, std::string_view)> terminal;  // one line, either way
  };

  Printer(PrinterConfig config, Store& store, Hooks hooks);
  ~Printer();
  Printer(const Printer&) = delete;
  Printer& operator=(const Printer&) = delete;

  void start();  // the thread; connects at once when autoconnect
  // Daemon shutdown: a running print stops streaming, heaters go off, and the print is left
  // "interrupted" with its last acknowledged command, ready to resume.
  void stop();

  // Each throws ApiError 409 when the printer's state does not allow it.
  void connect();
  void disconnect();
  long long print(const PrintRequest& request);  // the new print's id
  void pause();
  void resume();
  void cancel();
  void emergency_stop();
  void command(const std::vector<std::string>& commands);

  const std::string& id() const { return config_.id; }
  const PrinterConfig& config() const { return config_; }
  std::string state() const;
  std::string status_json() const;  // the whole status: state, temperatures, current/last print
  PrinterCounters counters() const;

 private:
  struct Throttle {
    std::chrono::steady_clock::time_point last_notify{}, last_save = std::chrono::steady_clock::now();
    std::chrono::steady_clock::time_point saves_paused_until{};  // after a full disk
  };
  void run();
  long long start_print(const PrintRequest& request);
  void open_link();
  void close_link(const std::string& state, const std::string& error);
  void handle_event(const protocol::marlin::SessionEvent& e, Throttle& throttle);
  void run_print(const PrintRequest& request, long long print_id,
                 const std::function<void(const protocol::marlin::SessionEvent&)>& on_event);
  void set_state(const std::string& state, const std::string& error = {});
  void notify(bool progress) const;

  PrinterConfig config_;
  Store& store_;
  Hooks hooks_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::thread thread_;
  bool stopping_ = false, connect_wanted_ = false, disconnect_wanted_ = false, estop_wanted_ = false;
  bool cancel_requested_ = false;  // the running print was cancelled (not failed) by a request
  bool commands_running_ = false;  // console commands are being streamed
  std::optional<PrintRequest> print_wanted_;
  long long print_wanted_id_ = 0;
  std::vector<std::vector<std::string>> commands_wanted_;

  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<protocol::serial::MarlinLink> link_;  // owned by the thread; pointer read under mutex_
  protocol::serial::MarlinLink* connecting_ = nullptr;  // during the handshake, under mutex_

  // The status, under mutex_.
  std::string state_ = "disconnected", error_, firmware_, device_;
  std::optional<double> hotend_, hotend_target_, bed_, bed_target_;
  struct Current {
    PrintRecord record;
    std::chrono::steady_clock::time_point started;
    long long confirmed = 0, total = 0;
  };
  std::optional<Current> current_;
  std::optional<PrintRecord> last_;
  PrinterCounters counters_;
};

}  // namespace salient::server
