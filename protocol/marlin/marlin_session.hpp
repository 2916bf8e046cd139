// MarlinSession: the host side of Marlin's line protocol as a pure state machine. The driver
// (Asio in the daemon, a simulator in tests, a fuzzer) feeds bytes and time, and writes out what
// take_output() returns; nothing here touches a port or a clock.
//
// States: idle → printing ⇄ paused → finished | failed | cancelled.
//
// A session that has not begun a print listens: to the handshake's M115 (firmware and capability
// events; oks_heard() counts the oks), and between prints to what the printer says unprompted
// (temperature reports, the replies to our M105 polls, errors, a restart), which become
// temperatures, error and reset events; on_tick sends the polls and, after idle_silence_limit
// without a byte, reports the printer lost (a timeout event, once).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/gcode/program.hpp"
#include "protocol/link/host_gap.hpp"
#include "protocol/marlin/marlin_reply.hpp"

namespace salient::protocol::marlin {

using protocol::Program;

using Millis = std::chrono::milliseconds;  // time since any fixed epoch, from the driver

enum class SessionState { idle, printing, paused, finished, failed, cancelled };

struct SessionConfig {
  // Silence with lines in flight is met with an M105 poke. The wait before it adapts to the
  // replies seen, as TCP's retransmission timer does (RFC 6298: srtt + 4·rttvar), within
  // [min_reply_timeout, reply_timeout], so a lost ok costs a fraction of a second on a quick link
  // and a slow printer is not poked; a command slow by nature (homing, heating, dwell, M400)
  // waits reply_timeout.
  Millis reply_timeout{10000};
  Millis min_reply_timeout{250};
  Millis busy_timeout{10000};  // after "busy:" or a heating report, wait this long before poking
  Millis poke_interval{2000};  // the longest wait between pokes while none is answered
  // A poke out and nothing at all heard for this long: the printer stopped answering, and the
  // print fails (resumable from what was confirmed). Slow commands get reply_timeout more; a
  // cancel, whose only job left is to turn the heaters off, cancel_silence_limit.
  Millis silence_limit{10000};
  Millis cancel_silence_limit{3000};
  // The firmware acts on M108 and M112 as they arrive (M115's Cap:EMERGENCY_PARSER): a cancel
  // breaks a heating wait with M108. Without it, a cancel during a wait sends M112.
  bool emergency_parser = false;
  int max_resends_of_one_line = 5;
  std::size_t rx_buffer_bytes = 128;  // the firmware's serial receive buffer (Marlin RX_BUFFER_SIZE)
  // Marlin follows "Resend: N" with "ok"; some versions do not. `detect` starts by expecting the
  // ok and stops after two requests went unanswered for resend_ok_wait without ever seeing one.
  enum class OkAfterResend { detect, yes, no } ok_after_resend = OkAfterResend::detect;
  Millis resend_ok_wait{500};
  // Between prints: an unnumbered M105 every idle_poll unless the firmware reports temperatures
  // itself (M115's Cap:AUTOREPORT_TEMP, turned on with M155); nothing heard for
  // idle_silence_limit means the printer is gone.
  bool autoreport_temperature = false;
  Millis idle_poll{2000};
  Millis idle_silence_limit{15000};
};

struct SessionEvent {
  enum class Kind {
    acknowledged,
    resend,
    temperatures,
    firmware,
    capability,
    action,
    error,
    reset,
    timeout,
    finished,
    failed
  };
  Kind kind;
  long long line = 0;  // acknowledged: how many commands are done; resend: the line asked for
  std::string text;    // error text, firmware name, capability, host action
  Temperatures temperatures;
};

class MarlinSession {
 public:
  explicit MarlinSession(SessionConfig config = {});

  // Starts a print of `program`, numbered after M110 N0; the commands are read from it as they
  // go out (it is shared, not copied). Resuming: the first `resume_from` commands count as done
  // and are not sent; `prelude` (temperatures, modes, position: see resume_prelude) goes first.
  void begin(std::shared_ptr<const Program> program, Millis now, std::size_t resume_from = 0,
             const std::vector<std::string>& prelude = {});
  // The same for a few lines (console commands, tests): one command per line.
  void begin(const std::vector<std::string>& commands, Millis now, std::size_t resume_from = 0,
             const std::vector<std::string>& prelude = {});
  void pause();
  void resume(Millis now);
  // Console lines during a print (a temperature, a fan, a flow rate): sent next, before the
  // program's next command, and while paused too (after the host's own lines); a cancel drops
  // those not sent yet. They do not count as the print's commands.
  void send_now(const std::vector<std::string>& lines, Millis now);
  // Stops sending the print; `cleanup` (heaters off, park) is sent next.
  void cancel(const std::vector<std::string>& cleanup, Millis now);
  // M112 at once, unnumbered (EMERGENCY_PARSER firmware acts on it even with a full queue).
  void emergency_stop();
  // True after a cancel had to halt the firmware (M112): it must be reset (reconnected).
  bool halted() const { return halted_; }

  void on_receive(std::string_view bytes, Millis now);
  void on_tick(Millis now);
  // The driver heard the printer elsewhere (a print's own session): the silence counts from `now`.
  void heard(Millis now) { last_heard_ = std::max(last_heard_, now); }
  std::size_t oks_heard() const { return oks_heard_; }  // listening: the replies that ended

  std::string take_output();
  std::vector<SessionEvent> take_events();
  Millis deadline() const { return std::min({reply_deadline_, resend_ok_deadline_, next_m108_}); }
  SessionState state() const { return state_; }
  bool idle() const { return nothing_to_send() && in_flight_.empty(); }  // nothing left to send or confirm
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
    bool counts;               // a print command (not M110 or a poke)
    bool reports_temperature;  // M105: its reply is "ok T:…", without ADVANCED_OK's N
    bool slow;                 // homing, heating, dwell…: its ok may take minutes
    bool waits_for_heat;       // M109/M190/M191: a cancel must break the wait
    bool resent;               // sent again: its reply time says nothing about the link (Karn)
    Millis sent_at;
  };
  bool nothing_to_send() const {
    return queue_.empty() && console_.empty() && next_command_ >= program_->size();
  }
  void drop_queue();  // nothing more of the program or the host's lines goes
  void handle(const MarlinReply& reply, Millis now);
  void listen(const MarlinReply& reply);  // between prints
  void listen_tick(Millis now);
  void handle_ok(const MarlinReply& reply, Millis now);
  void handle_resend(long long line, Millis now);
  void acknowledge(Millis now, bool sample = true);
  void pump(Millis now);
  void send_numbered(const std::string& command, bool counts, Millis now);
  void fail(const std::string& why);
  Millis timeout_for_front() const;  // how long the oldest line in flight may go unanswered
  void sample_reply_time(Millis sample);
  void check_silence(Millis now);
  void break_heating_wait(Millis now);

  SessionConfig config_;
  SessionState state_ = SessionState::idle;
  std::shared_ptr<const Program> program_ = std::make_shared<const Program>();
  std::size_t next_command_ = 0;                            // the program's next command to send
  std::deque<std::pair<std::string, bool>> queue_;          // host lines (command, counts) not yet sent
  std::deque<std::string> console_;                         // console lines during the print, not yet sent
  std::map<long long, std::pair<std::string, bool>> sent_;  // line → (command, counts), for resends
  std::deque<InFlight> in_flight_;
  long long next_line_ = 0;
  std::size_t bytes_in_flight_ = 0;
  int free_slots_ = 1;  // ADVANCED_OK's B at the last ok
  bool advanced_ok_ = false;
  bool expect_ok_after_resend_ = true;
  int resend_oks_due_ = 0;  // ping-pong: plain oks that answer Resend requests, not lines
  bool seen_ok_after_resend_ = false;
  int resend_oks_missed_ = 0;
  long long resend_line_ = -1;
  int resend_count_ = 0;
  int repeats_expected_ = 0;     // requests for resend_line_ still due from lines sent behind it
  bool checksum_error_ = false;  // the last Error: said checksum: the next Resend is genuine
  bool synchronising_ = false;
  std::size_t done_ = 0, total_ = 0, pokes_ = 0, resent_ = 0;
  Millis reply_deadline_{Millis::max()}, resend_ok_deadline_{Millis::max()};
  // Reply-time estimate (RFC 6298), and the poke schedule.
  bool have_rtt_ = false;
  double srtt_ms_ = 0, rttvar_ms_ = 0;
  Millis poke_wait_{0}, last_heard_{0};
  HostGap host_gap_;
  bool halted_ = false;
  Millis next_m108_{Millis::max()};  // a cancel during a heating wait: when M108 goes again
  std::optional<Millis> last_poll_;  // between prints: when M105 last went
  bool lost_ = false;                // between prints: the silence was reported
  std::size_t oks_heard_ = 0;
  long long resent_below_ = -1;  // lines numbered below this, sent after a rewind, are resends
  // What the machine is busy with: the least time of each command sent lately, as many as a
  // planner holds (Marlin's BLOCK_BUFFER_SIZE 16, plus its BUFSIZE 4).
  struct Motion {
    double pos[4] = {0, 0, 0, 0};
    double feed = 25;  // mm/s
    bool relative = false;
    Millis duration_of(std::string_view command);
  };
  static constexpr std::size_t kPlannerDepth = 20;
  Motion motion_;
  std::deque<Millis> recent_moves_;
  std::string partial_, output_;
  std::vector<SessionEvent> events_;
};

}  // namespace salient::protocol::marlin
