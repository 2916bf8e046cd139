// CommandQueue: what other threads asked a printer's thread to do, as typed requests instead of
// flags. The thread takes the most urgent one that can go now: a disconnect, then an emergency
// stop, then console batches (asked for before the print, or for now while it waits: a home
// asked for before a print must not move the head over the finished part), then the print.
// Not thread-safe: the Printer holds it under its mutex.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "protocol/gcode/program.hpp"

namespace salient::server {

struct PrintRequest {
  std::optional<std::string> job_id;
  std::string file_digest, filename;
  std::size_t resume_from = 0;  // commands already done (a resumed print)
};

struct ConnectCommand {};
struct DisconnectCommand {};
struct EmergencyStopCommand {};  // between prints: a print's own e-stop reaches the link at once
struct PrintCommand {
  PrintRequest request;
  long long print_id = 0;                            // its row, made when it was accepted
  std::shared_ptr<const protocol::Program> program;  // the file, read and checked when it was accepted
};
struct ConsoleCommand {
  std::vector<std::string> lines;
};
using PrinterCommand =
    std::variant<ConnectCommand, DisconnectCommand, EmergencyStopCommand, PrintCommand, ConsoleCommand>;

class CommandQueue {
 public:
  static constexpr std::size_t kMaxConsoleBatches = 16;

  // Connect, disconnect and e-stop are kept once each; a disconnect drops a waiting connect and
  // a connect a waiting disconnect. Console batches past kMaxConsoleBatches are the caller's to
  // refuse (console_full()).
  void push(PrinterCommand command);
  // The most urgent command that can go now: without a link, only a connect; with one, the rest
  // (a connect is then dropped: it is done).
  // `hold_print`: the print is paused before it began, and waits.
  std::optional<PrinterCommand> take(bool linked, bool hold_print = false);
  // The waiting print, out of the queue (cancelled before it began to stream).
  std::optional<PrintCommand> take_print();
  void clear() { connect_ = disconnect_ = estop_ = false, print_.reset(), console_.clear(); }

  bool print_waiting() const { return print_.has_value(); }
  bool console_full() const { return console_.size() >= kMaxConsoleBatches; }
  bool empty() const { return !connect_ && !disconnect_ && !estop_ && !print_ && console_.empty(); }
  bool connect_waiting() const { return connect_; }

 private:
  bool connect_ = false, disconnect_ = false, estop_ = false;
  std::optional<PrintCommand> print_;
  std::deque<ConsoleCommand> console_;
};

}  // namespace salient::server
