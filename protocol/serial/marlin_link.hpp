// MarlinLink: drives a MarlinSession over a Transport on the calling thread: the handshake
// (M115: firmware name and capabilities), then a print, until it is finished, failed, cancelled
// or the link drops. pause/resume/cancel/emergency_stop may be called from any other thread.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "protocol/gcode/program.hpp"
#include "protocol/marlin/marlin_session.hpp"
#include "protocol/serial/transport.hpp"

namespace salient::protocol::serial {

struct LinkConfig {
  marlin::SessionConfig session;
  std::chrono::milliseconds handshake_timeout{2000};  // per attempt; a board may still be booting
  int handshake_attempts = 3;
  int autoreport_seconds = 2;  // M155 S<n> when the firmware has AUTOREPORT_TEMP; 0: never
  // Sent after a cancel: heaters and fan off, lift, motors off.
  std::vector<std::string> cancel_gcode = {"M104 S0", "M140 S0", "M107", "G91", "G1 Z5 F600", "G90", "M84"};
  std::chrono::milliseconds interrupt_wait{2000};  // interrupt(): the longest wait for its heaters-off lines
  std::chrono::milliseconds idle_silence_limit{15000};  // idle(): nothing heard this long is a lost printer
};

struct FirmwareInfo {
  std::string name;
  bool emergency_parser = false, autoreport_temperature = false;
};

struct PrintResult {
  marlin::SessionState state = marlin::SessionState::idle;
  bool disconnected = false;  // the link dropped: `confirmed` is where to resume from
  std::size_t confirmed = 0, total = 0;
  std::string reason;   // why it stopped, when it did not finish
  bool halted = false;  // a cancel had to send M112: the firmware must be reset
  std::size_t lines_resent = 0, pokes = 0;
  double seconds = 0;
};

class MarlinLink {
 public:
  MarlinLink(std::unique_ptr<Transport> transport, LinkConfig config = {});

  // Throws LinkError when the printer does not answer.
  FirmwareInfo handshake();
  // `on_event` sees every session event, on this thread.
  PrintResult print(std::shared_ptr<const Program> program,
                    const std::function<void(const marlin::SessionEvent&)>& on_event = {},
                    std::size_t resume_from = 0, const std::vector<std::string>& prelude = {});

  // Between prints: listens for up to `duration` (temperature reports, errors, a reboot), and
  // polls with an unnumbered M105 every `poll` when the firmware does not auto-report. Events:
  // temperatures, error (fatal ones end with "failed"), reset. Throws LinkError.
  void idle(std::chrono::milliseconds duration,
            const std::function<void(const marlin::SessionEvent&)>& on_event,
            std::chrono::milliseconds poll = std::chrono::milliseconds(2000));
  // Writes one unnumbered line now (M112 when no print is running). Throws LinkError.
  void send_now(const std::string& line) { transport_->write(line + "\n"); }

  void pause() { request_ = kPause; }
  void resume() { request_ = kResume; }
  void cancel() { request_ = kCancel; }
  // Stops streaming and turns the heaters off, nothing else (no park, motors stay on): the print
  // can be resumed later from where it stopped. During handshake(): it gives up at once.
  void interrupt() { request_ = kInterrupt; }
  void emergency_stop() { request_ = kEmergency; }

  const FirmwareInfo& firmware() const { return firmware_; }

 private:
  enum Request { kNone, kPause, kResume, kCancel, kInterrupt, kEmergency };
  std::unique_ptr<Transport> transport_;
  LinkConfig config_;
  FirmwareInfo firmware_;
  std::atomic<int> request_{kNone};
  std::string idle_partial_;
  std::chrono::steady_clock::time_point last_poll_{}, idle_heard_ = std::chrono::steady_clock::now();
};

}  // namespace salient::protocol::serial
