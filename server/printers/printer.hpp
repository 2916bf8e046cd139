// Printer: one attached printer and the thread that owns its link (a protocol::PrinterLink: nothing
// here knows the protocol). The thread connects (open_printer_connection), listens between prints,
// runs prints and console commands, and writes each print's progress (the last acknowledged
// command) to the database as it goes. Requests from other threads are checked against the state
// (Conflict when they make no sense now) and queued for the thread (CommandQueue); pause, resume,
// cancel and emergency stop reach a running print at once.
//
// States (PrinterState): disconnected → connecting → operational ⇄ printing ⇄ paused; printing →
// finishing → operational (finishing: every command is confirmed, the print is being recorded);
// printing or paused → cancelling → operational; error after a failure (link lost, firmware
// halted, emergency stop, a connect that failed) until the next connect. Every change of state is
// also kept, with the status as it was then, for state_changes_since(): a watcher that reads the
// status after a hook may find a later state (a cancel ends within milliseconds), and OctoPrint's
// clients must see each one, in order.
//
// Threading. The printer's own thread (run(), printer_thread.cpp) alone creates, drives and
// destroys the link, and alone does blocking I/O: handshake, print, console commands, idle.
// Every other call (HTTP threads, the daemon's shutdown) takes mutex_, reads or changes the
// status and the queue, and wakes the thread; none waits on the printer. Those that reach a
// running link — pause, resume, cancel, emergency_stop, stop — call only the link's request
// methods, which set an atomic the link's loop reads on its next turn (at most 50 ms later);
// link_ (and connecting_, during a handshake) is read under mutex_, and the thread moves the link
// out under mutex_ before it destroys it, so no other thread ever holds a link that is going.
// The hooks are called without mutex_ held, from either kind of thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "protocol/marlin/extrusion_counter.hpp"
#include "server/config/daemon_config.hpp"
#include "server/printers/command_queue.hpp"
#include "server/printers/printer_status.hpp"
#include "server/printers/progress_saver.hpp"
#include "server/store/print_store.hpp"
#include "server/store/store.hpp"

namespace salient::protocol {
class Program;
class PrinterLink;
struct LinkEvent;
struct PrintResult;
}  // namespace salient::protocol

namespace salient::server {

class SimProcess;

struct PrinterCounters {
  long long lines_sent = 0, lines_resent = 0, prints_finished = 0, prints_failed = 0;
};

class Printer {
 public:
  struct Hooks {
    std::function<void(const Printer&, bool progress)> changed;  // state (false) or progress (true)
    std::function<bool(const Printer&)> terminal_wanted;         // someone watches terminal/{id}
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

  // Each throws Conflict (409) when the printer's state does not allow it; print throws
  // Unprocessable (422) for a file that cannot be printed, command TooBusy (429) when 16 batches
  // wait already.
  void connect();
  void disconnect();
  long long print(const PrintRequest& request);  // the new print's id
  void pause();
  void resume();
  void cancel();
  void emergency_stop();
  // While a print streams, a command that moves or homes the head (G28, G1, G92, M84…) is a
  // Conflict unless `force`: it would spoil the print (OctoPrint refuses jog and home then too).
  void command(const std::vector<std::string>& commands, bool force = false);

  const std::string& id() const { return config_.id; }
  const PrinterConfig& config() const { return config_; }
  PrinterState state() const;
  PrinterStatus status() const;  // the whole status: state, temperatures, current/last print
  PrinterCounters counters() const;
  // The status at each change of state after `seq` (0: from the oldest kept), oldest first; `seq`
  // is moved past them. Only the last kMaxStateChanges are kept: a watcher that falls further
  // behind misses the oldest.
  static constexpr std::size_t kMaxStateChanges = 64;
  std::vector<PrinterStatus> state_changes_since(std::uint64_t& seq) const;

 private:
  struct Throttle {
    std::chrono::steady_clock::time_point last_notify{}, last_save = std::chrono::steady_clock::now();
  };
  // Replug (printer_replug.cpp): a serial printer whose link went away by itself (unplugged, the
  // board reset, the device not there at start) is connected again when its device path is back.
  struct Replug {
    bool present = true;  // the device path existed at the last look
    std::chrono::steady_clock::time_point last_try{};
    std::string tried;  // the device node last tried (printer_replug.cpp: identity())
  };
  static constexpr std::chrono::seconds kReplugPoll{2};
  void poll_replug(Replug& replug);
  using EventFn = std::function<void(const protocol::LinkEvent&)>;
  // printer.cpp: what other threads call.
  long long start_print(const PrintRequest& request);
  void refuse_unless_ready() const;  // under mutex_
  [[noreturn]] void conflict(const std::string& message) const;
  void notify(bool progress) const;
  // The current print's state (printing or paused), confirmed lines and usage, written to the
  // store now; false when the store refused (a full disk). Writes are serialized and each reads
  // the state inside, so a progress write read before a pause cannot land after the pause's.
  bool save_progress();
  // printer_thread.cpp: the printer's own thread.
  void run();
  void run_console(const std::vector<std::string>& lines, const EventFn& on_event);
  void open_link();
  void close_link(PrinterState state, const std::string& error);
  void handle_event(const protocol::LinkEvent& e, Throttle& throttle);
  void run_print(const PrintCommand& print, const EventFn& on_event);
  void drop_waiting_print();  // under mutex_: a cancel before the print streamed
  PrintState print_outcome(const protocol::PrintResult& result, bool interrupted, bool cancelled) const;
  void set_state(PrinterState state, const std::string& error = {});
  // Under mutex_: the state (and its error) changes, and the change is kept.
  void enter(PrinterState state, const std::string& error = {});
  PrinterStatus status_locked() const;

  PrinterConfig config_;
  Store& store_;
  Hooks hooks_;

  mutable std::mutex mutex_;
  std::mutex save_mutex_;  // one save_progress() at a time; taken before mutex_
  ProgressSaver saver_{[this] { return save_progress(); }};  // the print's progress, off the thread
  std::condition_variable wake_;
  std::thread thread_;
  bool stopping_ = false;
  CommandQueue queue_;
  bool cancel_requested_ = false;  // the running print was cancelled (not failed) by a request
  // The thread has taken the print and streams it: pause, resume and cancel go to the link. Before
  // that (console batches ahead of it), they are the queue's: a request sent to the link then would
  // end the console batch instead, and the print would run as if never cancelled.
  bool print_streaming_ = false;
  bool pause_pending_ = false;     // paused before it began to stream: the link is told when it does
  bool commands_running_ = false;  // console commands are being streamed
  // The thread's alone: the printer should be connected (a connect was asked for, and no
  // disconnect, emergency stop or firmware failure since), so a lost link is reconnected when
  // the device is back.
  bool replug_ = false;

  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<protocol::PrinterLink> link_;  // owned by the thread; pointer read under mutex_
  protocol::PrinterLink* connecting_ = nullptr;  // during the handshake, under mutex_

  // The status, under mutex_.
  PrinterState state_ = PrinterState::disconnected;
  std::string error_, firmware_, device_;
  Temperature hotend_, bed_;
  struct Current {
    PrintRecord record;
    std::chrono::steady_clock::time_point started;
    long long confirmed = 0, total = 0;
    std::size_t file_bytes = 0;                                  // the file's size
    std::shared_ptr<const protocol::Program> program;            // for the layer and byte under way
    std::optional<protocol::marlin::ExtrusionCounter> extruded;  // over *program, to `confirmed`
    std::optional<std::chrono::steady_clock::time_point> paused_since;
    double paused_seconds = 0;  // pauses ended
    PrintUsage usage() const;
  };
  std::optional<Current> current_;
  std::optional<PrintRecord> last_;
  PrinterCounters counters_;
  std::deque<PrinterStatus> changes_;  // the last kMaxStateChanges changes of state
  std::uint64_t changes_end_ = 0;      // sequence number of the newest (changes_.back())
};

}  // namespace salient::server
