// PrinterLink: one printer's connection as a host drives it, whatever the protocol — Marlin's
// numbered G-code lines now (serial::MarlinLink), s3g's packets next. The daemon's Printer and the
// CLI's print command hold one and see only these types.
//
// Threading: handshake, print, idle and halt_now block on the one thread that drives the link.
// The requests (pause, resume, cancel, interrupt, emergency_stop) may come from any other thread:
// each only sets an atomic that the driving loop reads on its next turn (within 50 ms).
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "protocol/gcode/program.hpp"

namespace salient::protocol {

// The link is gone (cable pulled, bridge closed), could not be opened, or the printer stopped
// answering between prints.
class LinkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct FirmwareInfo {
  std::string name;
  bool emergency_parser = false, autoreport_temperature = false;
};

// What a host needs to hear while it drives a printer, without the protocol's own vocabulary.
struct LinkEvent {
  enum class Kind {
    progress,      // `done` commands of the print are confirmed
    temperatures,  // a report: the fields it gave are set
    resend,        // the printer asked for a line again (a noisy link)
    error,         // the printer reported an error (`text`); a fatal one also ends the print
    reset          // the printer restarted
  };
  Kind kind;
  std::size_t done = 0;
  std::string text;
  std::optional<double> hotend, hotend_target, bed, bed_target;  // °C
};
using LinkEventFn = std::function<void(const LinkEvent&)>;

enum class PrintEnd { finished, cancelled, failed };

struct PrintResult {
  PrintEnd end = PrintEnd::failed;
  bool disconnected = false;  // the link dropped: `confirmed` is where to resume from
  std::size_t confirmed = 0, total = 0;
  std::string reason;   // why it stopped, when it did not finish
  bool halted = false;  // a cancel had to halt the firmware: it must be reset (reconnected)
  std::size_t lines_resent = 0, pokes = 0;
  double seconds = 0;
  std::vector<std::string> unsent;  // console lines sent into the print after it ended (send())
};

class PrinterLink {
 public:
  virtual ~PrinterLink() = default;

  // Who the printer is and what it can do. Throws LinkError when it does not answer.
  virtual FirmwareInfo handshake() = 0;
  // Streams `program` until it is finished, failed or cancelled, or the link drops (the result
  // says which; a dropped link is not thrown). Resuming: the first `resume_from` commands count
  // as done, and the link first restores what they left (temperatures, modes, position).
  virtual PrintResult print(std::shared_ptr<const Program> program, const LinkEventFn& on_event = {},
                            std::size_t resume_from = 0) = 0;
  // Between prints: listens for up to `duration` (temperatures, errors, a restart), asking for
  // temperatures now and then when the printer does not report them itself. Throws LinkError,
  // also when the printer has been silent too long.
  virtual void idle(std::chrono::milliseconds duration, const LinkEventFn& on_event) = 0;
  // Emergency stop while nothing streams: the firmware halts at once. Throws LinkError.
  virtual void halt_now() = 0;

  // From any thread, into a running print.
  virtual void pause() = 0;
  virtual void resume() = 0;
  virtual void cancel() = 0;  // stop, heaters off, head lifted, motors off
  // Stops streaming and turns the heaters off, nothing else (no park, motors stay on): the print
  // can be resumed later from where it stopped. During handshake(): it gives up at once.
  virtual void interrupt() = 0;
  virtual void emergency_stop() = 0;
  // From any thread, into a running print: console lines that go next (also while paused), as
  // OctoPrint sends a temperature or a flow rate during a print. False: this link takes commands
  // between prints only. Lines the print ends before sending come back in PrintResult::unsent.
  virtual bool send(const std::vector<std::string>& lines) {
    (void)lines;
    return false;
  }
};

}  // namespace salient::protocol
