// S3gLink: the PrinterLink of MakerBot/Sailfish boards. It drives an S3gSession over a Transport
// on the calling thread: the handshake (version and advanced version: Sailfish or not), then a
// print of x3g actions until it is finished, failed, cancelled or the link drops; between prints,
// it listens (temperatures, silence).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "protocol/gcode/program.hpp"
#include "protocol/link/printer_link.hpp"
#include "protocol/s3g/s3g_session.hpp"
#include "protocol/s3g/x3g_program.hpp"
#include "protocol/serial/transport.hpp"

namespace salient::protocol::serial {

using protocol::FirmwareInfo;
using protocol::LinkEvent;
using protocol::LinkEventFn;
using protocol::PrintEnd;
using protocol::PrinterLink;
using protocol::PrintResult;

struct S3gLinkConfig {
  s3g::SessionConfig session;
  // G-code → x3g for print(Program): the caller provides the translator (empty: print() fails
  // with a reason saying so).
  std::function<s3g::X3gProgram(const Program&)> translate;
  // Actions sent before a resumed print's first command (empty function: s3g::resume_prelude).
  std::function<std::vector<std::string>(const s3g::X3gProgram&, std::size_t resume_from)> resume_prelude;
  std::chrono::milliseconds handshake_timeout{2000};  // per attempt
  int handshake_attempts = 3;
  std::chrono::milliseconds interrupt_wait{
      2000};  // interrupt(): the longest wait for its heaters-off actions
};

class S3gLink : public PrinterLink {
 public:
  S3gLink(std::unique_ptr<Transport> transport, S3gLinkConfig config = {});

  // Queries 0 and 27. Throws LinkError when the board does not answer.
  FirmwareInfo handshake() override;
  // Translates with config.translate, then print_x3g.
  PrintResult print(std::shared_ptr<const Program> program, const LinkEventFn& on_event = {},
                    std::size_t resume_from = 0) override;
  // An .x3g given directly (or translated): resume_from counts the program's commands.
  PrintResult print_x3g(std::shared_ptr<const s3g::X3gProgram> program, const LinkEventFn& on_event = {},
                        std::size_t resume_from = 0);
  // The same with the prelude given (whole action payloads); print_x3g uses config.resume_prelude.
  PrintResult print_x3g(std::shared_ptr<const s3g::X3gProgram> program, const LinkEventFn& on_event,
                        std::size_t resume_from, std::vector<std::string> prelude);
  void idle(std::chrono::milliseconds duration, const LinkEventFn& on_event) override;
  // Query 22 extended stop (halt, clear the ring), unanswered.
  void halt_now() override;

  void pause() override { request_ = kPause; }
  void resume() override { request_ = kResume; }
  void cancel() override { request_ = kCancel; }
  void interrupt() override { request_ = kInterrupt; }
  void emergency_stop() override { request_ = kEmergency; }

  const FirmwareInfo& firmware() const { return firmware_; }
  // The last print's counters.
  std::size_t doubts_resolved() const { return doubts_; }

 private:
  enum Request { kNone, kPause, kResume, kCancel, kInterrupt, kEmergency };
  s3g::Millis since_start() const;
  std::unique_ptr<Transport> transport_;
  S3gLinkConfig config_;
  FirmwareInfo firmware_;
  std::atomic<int> request_{kNone};
  std::chrono::steady_clock::time_point start_;
  std::unique_ptr<s3g::S3gSession> idle_;
  std::size_t doubts_ = 0;
};

}  // namespace salient::protocol::serial
