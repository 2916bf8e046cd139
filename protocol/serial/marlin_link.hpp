// MarlinLink: the PrinterLink of Marlin printers. It drives a MarlinSession over a Transport on
// the calling thread: the handshake (M115: firmware name and capabilities), then a print, until
// it is finished, failed, cancelled or the link drops; between prints, it listens.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "protocol/gcode/program.hpp"
#include "protocol/link/printer_link.hpp"
#include "protocol/marlin/marlin_session.hpp"
#include "protocol/serial/transport.hpp"

namespace salient::protocol::serial {

using protocol::PrinterLink;

struct LinkConfig {
  marlin::SessionConfig session;
  std::chrono::milliseconds handshake_timeout{2000};  // per attempt; a board may still be booting
  int handshake_attempts = 3;
  int autoreport_seconds = 2;  // M155 S<n> when the firmware has AUTOREPORT_TEMP; 0: never
  // Sent after a cancel: heaters and fan off, lift, motors off.
  std::vector<std::string> cancel_gcode = {"M104 S0", "M140 S0", "M107", "G91", "G1 Z5 F600", "G90", "M84"};
  std::chrono::milliseconds interrupt_wait{2000};  // interrupt(): the longest wait for its heaters-off lines
};

using protocol::FirmwareInfo;
using protocol::LinkEvent;
using protocol::LinkEventFn;
using protocol::PrintEnd;
using protocol::PrintResult;

class MarlinLink : public PrinterLink {
 public:
  MarlinLink(std::unique_ptr<Transport> transport, LinkConfig config = {});

  // M115 (and M155 S<n> with AUTOREPORT_TEMP). Throws LinkError when the printer does not answer.
  FirmwareInfo handshake() override;
  // The prelude of a resumed print is resume_prelude's. `on_event` sees the session's events
  // that a host needs, on this thread.
  PrintResult print(std::shared_ptr<const Program> program, const LinkEventFn& on_event = {},
                    std::size_t resume_from = 0) override;
  // A MarlinSession that begun no print listens (temperatures, errors, restarts, polls, silence).
  void idle(std::chrono::milliseconds duration, const LinkEventFn& on_event) override;
  // M112, unnumbered.
  void halt_now() override { transport_->write("M112\n"); }

  void pause() override { request_ = kPause; }
  void resume() override { request_ = kResume; }
  void cancel() override { request_ = kCancel; }
  void interrupt() override { request_ = kInterrupt; }
  void emergency_stop() override { request_ = kEmergency; }
  bool send(const std::vector<std::string>& lines) override;

  const FirmwareInfo& firmware() const { return firmware_; }

 private:
  enum Request { kNone, kPause, kResume, kCancel, kInterrupt, kEmergency };
  std::unique_ptr<Transport> transport_;
  LinkConfig config_;
  FirmwareInfo firmware_;
  std::atomic<int> request_{kNone};
  std::mutex send_mutex_;
  std::vector<std::string> to_send_;  // console lines for the running print, under send_mutex_
  std::vector<std::string> take_to_send();
  marlin::Millis since_start() const;  // the listening sessions' clock
  bool exchange(marlin::MarlinSession& listener, const std::string& command,
                std::vector<marlin::SessionEvent>& heard);
  std::chrono::steady_clock::time_point start_;
  std::unique_ptr<marlin::MarlinSession> idle_;  // between prints: listens (made by the handshake)
};

}  // namespace salient::protocol::serial
