// MarlinSession: the host side of Marlin's line protocol as a pure state machine. The driver
// (Asio in the daemon, a simulator in tests, a fuzzer) feeds bytes and time, and writes out what
// take_output() returns; nothing here touches a port or a clock.
//
// States: idle → printing ⇄ paused → finished | failed | cancelled.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <deque>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/marlin/marlin_reply.hpp"

namespace salient::protocol::marlin {

using Millis = std::chrono::milliseconds;  // time since any fixed epoch, from the driver

enum class SessionState { idle, printing, paused, finished, failed, cancelled };

struct SessionConfig {
  Millis reply_timeout{10000};  // nothing heard for this long with lines in flight: poke with M105
  Millis busy_timeout{60000};   // after "busy:", wait this long before poking
  int max_resends_of_one_line = 5;
  std::size_t rx_buffer_bytes = 128;  // the firmware's serial receive buffer (Marlin RX_BUFFER_SIZE)
  // Marlin follows "Resend: N" with "ok"; some versions do not. `detect` starts by expecting the
  // ok and stops after two requests went unanswered for resend_ok_wait without ever seeing one.
  enum class OkAfterResend { detect, yes, no } ok_after_resend = OkAfterResend::detect;
  Millis resend_ok_wait{500};
};

struct SessionEvent {
  enum class Kind { acknowledged, resend, temperatures, firmware, capability, action, error, reset, timeout, finished, failed };
  Kind kind;
  long long line = 0;      // acknowledged: how many commands are done; resend: the line asked for
  std::string text;        // error text, firmware name, capability, host action
  Temperatures temperatures;
};

class MarlinSession {
 public:
  explicit MarlinSession(SessionConfig config = {});

  // Starts a print of `gcode` (comments stripped, blank lines skipped), numbered after M110 N0.
  // Resuming: the first `resume_from` commands count as done and are not sent; `prelude`
  // (temperatures, modes, position: see resume_prelude) goes first.
  void begin(const std::vector<std::string>& gcode, Millis now, std::size_t resume_from = 0,
             const std::vector<std::string>& prelude = {});
  void pause();
  void resume(Millis now);
  // Stops sending the print; `cleanup` (heaters off, park) is sent next.
  void cancel(const std::vector<std::string>& cleanup, Millis now);
  // M112 at once, unnumbered (EMERGENCY_PARSER firmware acts on it even with a full queue).
  void emergency_stop();

  void on_receive(std::string_view bytes, Millis now);
  void on_tick(Millis now);

  std::string take_output();
  std::vector<SessionEvent> take_events();
  Millis deadline() const { return std::min(reply_deadline_, resend_ok_deadline_); }
  SessionState state() const { return state_; }
  bool idle() const { return queue_.empty() && in_flight_.empty(); }  // nothing left to send or confirm
  std::size_t commands_done() const { return done_; }
  std::size_t commands_total() const { return total_; }
  bool advanced_ok() const { return advanced_ok_; }
  // Lines sent that the host itself added (M110, timeout pokes), and lines sent again on request.
  std::size_t pokes_sent() const { return pokes_; }
  std::size_t lines_resent() const { return resent_; }

 private:
  struct InFlight {
    long long line;
    std::size_t bytes;
    bool counts;            // a print command (not M110 or a poke)
    bool reports_temperature;  // M105: its reply is "ok T:…", without ADVANCED_OK's N
  };
  void handle(const MarlinReply& reply, Millis now);
  void handle_ok(const MarlinReply& reply, Millis now);
  void handle_resend(long long line, Millis now);
  void acknowledge(Millis now);
  void pump(Millis now);
  void send_numbered(const std::string& command, bool counts, Millis now);
  void fail(const std::string& why);

  SessionConfig config_;
  SessionState state_ = SessionState::idle;
  std::deque<std::pair<std::string, bool>> queue_;  // (command, counts) not yet sent
  std::map<long long, std::pair<std::string, bool>> sent_;  // line → (command, counts), for resends
  std::deque<InFlight> in_flight_;
  long long next_line_ = 0;
  std::size_t bytes_in_flight_ = 0;
  int free_slots_ = 1;  // ADVANCED_OK's B at the last ok
  bool advanced_ok_ = false;
  bool expect_ok_after_resend_ = true;
  int resend_oks_due_ = 0;         // ping-pong: plain oks that answer Resend requests, not lines
  bool seen_ok_after_resend_ = false;
  int resend_oks_missed_ = 0;
  long long resend_line_ = -1;
  int resend_count_ = 0;
  int repeats_expected_ = 0;  // requests for resend_line_ still due from lines sent behind it
  bool checksum_error_ = false;  // the last Error: said checksum: the next Resend is genuine
  bool synchronising_ = false;
  std::size_t done_ = 0, total_ = 0, pokes_ = 0, resent_ = 0;
  Millis reply_deadline_{Millis::max()}, resend_ok_deadline_{Millis::max()};
  std::string partial_, output_;
  std::vector<SessionEvent> events_;
};

}  // namespace salient::protocol::marlin
