// S3gSession: the host side of s3g as a pure state machine, in the shape of MarlinSession. The
// driver feeds bytes and time and writes out what take_output() returns; nothing here touches a
// port or a clock.
//
// States: idle → printing ⇄ paused → finished | failed | cancelled.
//
// One packet is in flight at a time, and every packet gets exactly one reply. An action (≥ 128)
// is queued in the board's 512-byte ring when its reply is 81; 82 means it did not fit and was
// not queued (poll query 2 until it fits, send again). s3g has no sequence numbers, so a lost or
// garbled reply to an action leaves a doubt: was it queued? The session never sends an action
// twice: it reads a consistent snapshot (build stats `line` L1, free space F, `line` L2 == L1) and
// compares the ring's occupancy (512 − F) with the bytes it knows are queued — the payloads it
// had accepted, less those of the actions the board has started (`line` counts them) — with and
// without the doubtful action. Occupancy below what is known queued, or `line` going backwards,
// means the board reset: the print fails, resumable from the commands whose actions all started.
//
// A session that never began a print listens: handshake() asks the version (0) and the advanced version
// (27: variant 0x80 is Sailfish); on_tick polls temperatures; silence becomes a timeout event.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/link/host_gap.hpp"
#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/x3g_program.hpp"

namespace salient::protocol::s3g {

using Millis = std::chrono::milliseconds;  // time since any fixed epoch, from the driver

enum class SessionState { idle, printing, paused, finished, failed, cancelled };

struct SessionConfig {
  // The wait for a reply's first byte adapts to the replies seen, as TCP's retransmission timer
  // does (RFC 6298: srtt + 4·rttvar), within [min_reply_timeout, reply_timeout]: a board answers
  // every packet at once (an action that does not fit is 82, not a wait), so a lost reply costs a
  // fraction of a second rather than pyS3g's and GPX's fixed 1 s. A premature timeout costs a
  // ring snapshot, never a duplicate.
  Millis reply_timeout{1000};
  Millis min_reply_timeout{150};
  Millis byte_timeout{100};  // between the bytes of one reply, and after bytes that made none
  Millis quiet_gap{5};       // after a doubt, the line must be quiet this long before we send
  int max_resends = 5;       // of one packet on 80/83/88/8C
  // Nothing heard for this long while a packet waits: the board is gone, the print fails
  // (resumable from what was confirmed).
  Millis silence_limit{10000};
  // Query 2 while an action waits for room (82): quickly at first (a move or two runs out in
  // tens of ms), then at a slower pace (a heating wait may hold the ring for minutes).
  Millis buffer_poll_fast{10};
  int fast_polls = 20;
  Millis buffer_poll{100};
  Millis stats_poll{1000};        // build stats (24) while printing
  Millis temperature_poll{2000};  // the four temperature queries (10) while printing
  Millis pause_check{200};        // build stats while a pause or resume is unconfirmed
  Millis pause_confirm{3000};     // a toggle not confirmed by then is checked and sent again
  int max_toggles = 3;
  Millis idle_poll{2000};
  Millis idle_silence_limit{15000};
  std::size_t ring_bytes = 512;  // Sailfish's command buffer
  int snapshot_attempts = 20;    // for a consistent (L1, F, L2)
  int max_garbled = 50;          // replies in a row that make no sense: the line is not s3g
  std::uint16_t host_version = 100;
};

// °C; a report sets the pair it answers.
struct Temperatures {
  std::optional<double> hotend, hotend_target, bed, bed_target;
};

struct SessionEvent {
  enum class Kind {
    acknowledged,  // `done` commands are confirmed
    resend,        // a packet goes again (noise)
    temperatures,
    firmware,  // `text`: "Sailfish 7.7"
    error,     // `text`: a warning that does not end the print
    paused,    // the board confirmed the pause (build stats: paused)
    resumed,
    reset,    // the board restarted
    timeout,  // between prints: the board stopped answering
    finished,
    failed,
    cancelled
  };
  Kind kind;
  std::size_t done = 0;
  std::string text;
  Temperatures temperatures;
};

// Build stats (query 24), per the protocol's layout.
struct BuildStats {
  enum State : std::uint8_t {
    none = 0,
    running = 1,
    finished = 2,
    paused = 3,
    cancelled = 4,
    cancelling = 5
  };
  std::uint8_t state = none, hours = 0, minutes = 0;
  std::uint32_t line = 0;  // actions the board has started since power-on
};

class S3gSession {
 public:
  explicit S3gSession(SessionConfig config = {});

  // Listening: asks version (0) and advanced version (27); handshake_done() when both answered.
  void handshake(Millis now);
  bool handshake_done() const { return handshake_done_; }
  const std::string& firmware_name() const { return firmware_name_; }
  std::uint16_t firmware_version() const { return firmware_version_; }
  bool sailfish() const { return variant_ == 0x80; }

  // Starts a print of `program` (shared, not copied). Resuming: the first `resume_from` commands
  // count as done and their actions are not sent; `prelude` (whole action payloads) goes first.
  void begin(std::shared_ptr<const X3gProgram> program, Millis now, std::size_t resume_from = 0,
             std::vector<std::string> prelude = {});
  // Query 8 (a toggle) confirmed by build stats: paused (3); resume toggles back, confirmed by
  // running. Nothing more is sent until the board has confirmed.
  void pause();
  void resume(Millis now);
  // Stops sending the print. clear_ring: query 7 abort first (what was queued is dropped), else
  // the ring runs out (interrupt: the print resumes from what was confirmed). Then `cleanup`.
  void cancel(const std::vector<std::string>& cleanup, Millis now, bool clear_ring = true);
  // Query 22 extended stop (halt and clear) at once, then `cleanup`.
  void emergency_stop(const std::vector<std::string>& cleanup, Millis now);

  void on_receive(std::string_view bytes, Millis now);
  void on_tick(Millis now);
  void heard(Millis now) { last_heard_ = std::max(last_heard_, now); }

  std::string take_output();
  std::vector<SessionEvent> take_events();
  Millis deadline() const;
  SessionState state() const { return state_; }
  bool idle() const { return !in_flight_ && control_.empty() && !retry_; }  // nothing left to send or confirm
  bool pause_confirmed() const { return board_paused_; }
  // Commands confirmed (all their actions accepted); after a reset, those whose actions all started.
  std::size_t commands_done() const { return done_; }
  std::size_t commands_total() const { return program_ ? program_->commands : 0; }
  std::size_t packets_resent() const { return resent_; }
  std::size_t doubts_resolved() const { return doubts_queued_ + doubts_not_queued_; }
  std::size_t doubts_queued() const { return doubts_queued_; }  // the board had it: not sent again
  std::size_t doubts_not_queued() const { return doubts_not_queued_; }
  std::size_t timeouts() const { return timeouts_; }

  // Heaters off (tool 0 and platform) and motors off: the cleanup of a cancel.
  static std::vector<std::string> heaters_off();
  static std::vector<std::string> cancel_cleanup();

 private:
  enum class Purpose {
    action,
    version,
    advanced_version,
    buffer_space,
    build_stats,
    temperature,
    pause_toggle,
    abort,
    extended_stop
  };
  struct Packet {
    std::string payload;
    Purpose purpose = Purpose::action;
    bool counted = false;  // a print action: never sent twice, accounted for in the ring
    int tries = 0;
  };
  struct Snapshot {
    int step = 0;  // 0: ask L1, 1: ask F, 2: ask L2
    std::uint32_t l1 = 0, free = 0;
    int attempts = 0;
    std::optional<Packet> doubtful;  // the action whose reply was lost
    bool after_error = false;        // its reply asked for a resend (counted already)
  };

  void send(Packet p, Millis now);
  void pump(Millis now);
  std::optional<Packet> next_packet(Millis now);
  void on_reply(std::string_view payload, Millis now);
  void on_garbled(Millis now, const char* why);
  void on_accept(const Packet& p, std::string_view data, Millis now);
  void on_stats(const BuildStats& s, Millis now);
  void resolve(Millis now);
  void accept_action(const Packet& p);
  void reset_detected();
  void fail(const std::string& why);
  void end(SessionState s, const std::string& why);
  void retry(Packet p, Millis now);
  void check_silence(Millis now);
  bool printing_phase() const { return state_ == SessionState::printing || state_ == SessionState::paused; }
  std::size_t done_for(std::size_t program_actions) const;
  std::size_t started_program_actions() const;

  SessionConfig config_;
  SessionState state_ = SessionState::idle;
  std::shared_ptr<const X3gProgram> program_;
  std::vector<std::string> prelude_;
  std::size_t prelude_next_ = 0, start_action_ = 0, next_action_ = 0, resume_from_ = 0;
  std::optional<Packet> current_;  // the action being sent (not yet accepted)
  std::optional<Packet> retry_;    // a packet to send again, first
  std::deque<Packet> control_;
  Millis control_not_before_{0};      // a cleanup action refused (82) waits for room        // host packets
                                      // (handshake, abort, cleanup): before the print
  std::optional<Snapshot> snapshot_;  // a doubt being resolved (or a begin's baseline)
  bool need_room_ = false;            // current_ got 82: poll query 2 until it fits
  Millis next_room_poll_{0};
  int room_polls_ = 0;
  // Ring accounting: actions accepted in order (their sizes), the first at sequence accepted_base_.
  std::deque<std::size_t> accepted_sizes_;
  std::size_t accepted_base_ = 0, accepted_count_ = 0;
  bool have_baseline_ = false;
  std::uint32_t line_base_ = 0, last_line_ = 0;
  bool seen_building_ = false;
  std::optional<Packet> in_flight_packet_;
  bool in_flight_ = false, got_bytes_ = false;
  Millis reply_deadline_{Millis::max()};
  // Reply-time estimate (RFC 6298) from packets sent once (Karn: a resent one's reply is ambiguous).
  Millis sent_at_{0};
  bool sample_reply_ = false, have_rtt_ = false;
  double srtt_ms_ = 0, rttvar_ms_ = 0;
  Millis reply_wait() const;
  void sample_reply_time(Millis sample);
  PacketDecoder decoder_;
  bool quiet_ = false;  // discarding the line's bytes until quiet_until_
  Millis quiet_until_{0};
  Millis last_heard_{0};
  HostGap host_gap_;
  Millis next_stats_{0}, next_temps_{0};
  int temp_step_ = 4;  // 0…3: the temperature queries of a round; 4: none due
  Temperatures temps_;
  // Pause / resume: the goal and the last toggle.
  std::optional<bool> want_paused_;
  bool board_paused_ = false;
  bool stats_fresh_ = false;  // a build stats reply came after the last toggle
  std::optional<Millis> toggled_at_;
  int toggles_ = 0;
  std::uint8_t state_before_pause_ = BuildStats::running;
  bool began_ = false;   // a print session: it does not go on listening when the print ends
  bool ending_ = false;  // cancel: drain control_, then cancelled
  bool finishing_ = false;
  // Handshake and listening.
  bool handshake_done_ = false, handshaking_ = false;
  std::uint16_t firmware_version_ = 0;
  std::uint8_t variant_ = 0;
  std::string firmware_name_;
  bool lost_ = false;
  std::optional<Millis> last_poll_;
  int garbled_run_ = 0;
  std::size_t done_ = 0, resent_ = 0, doubts_queued_ = 0, doubts_not_queued_ = 0, timeouts_ = 0;
  std::string output_;
  std::vector<SessionEvent> events_;
};

}  // namespace salient::protocol::s3g
