// SimFirmware: a Marlin-like printer as a pure state machine: bytes and time in; bytes out, and
// the log of every command it executed, in order. The driver (salient-sim over a pseudo-terminal,
// or a test) moves the bytes and keeps the clock.
//
// What it models, after Marlin 2.1 (src/gcode/queue.cpp, gcode.cpp, module/planner.cpp):
// a receive buffer that drops what does not fit; line numbers and checksums checked in Marlin's
// order, the receive buffer flushed on an error and "Resend: N" (+ "ok"); a command queue of
// BUFSIZE slots read only while a slot is free; "ok" sent once a command is processed (a move is
// processed when it enters the planner), with ADVANCED_OK's "ok N P B"; a planner of
// BLOCK_BUFFER_SIZE moves that take time (trapezoids from feed rate and acceleration); heaters
// that take time, with busy keepalives and temperature reports while M109/M190 wait; M105,
// M115, M155 auto-report; the emergency parser (M108, M112, M410 as bytes arrive); and faults
// (sim_faults.hpp), among them a board that hangs or reboots: states silent and booting.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/sim/sim_faults.hpp"
#include "protocol/sim/wire.hpp"

namespace salient::protocol::sim {

struct SimConfig {
  std::size_t rx_buffer_bytes = 128;  // RX_BUFFER_SIZE
  std::size_t bufsize = 4;            // BUFSIZE: commands queued
  std::size_t planner_blocks = 16;    // BLOCK_BUFFER_SIZE
  bool advanced_ok = false;
  bool emergency_parser = false;
  bool autoreport = false;               // M155
  double baud = 0;                       // bits per second on the wire, 10 per byte; 0: no limit
  double time_scale = 0;                 // wall seconds per printer second for motion; 0: instant
  double heat_time_scale = -1;           // the same for heaters; negative: as time_scale
  double acceleration = 1000;            // mm/s², until M204
  double hotend_rate = 3, bed_rate = 1;  // °C/s
  SimFaults faults;
};

struct SimStats {
  long long executed = 0;
  long long lines_received = 0;
  long long lines_rejected = 0;     // line number or checksum errors
  long long lines_corrupted = 0;    // by the noise fault
  long long rx_overflow_bytes = 0;  // dropped: the host sent more than the buffer holds
  long long oks_dropped = 0;
  long long lines_after_halt = 0;   // lines the host sent after the firmware halted
  long long bytes_ignored = 0;      // arrived while silent or booting, and lost
  long long lines_rerequested = 0;  // intact, but asked for again (rerequest)
  long long oks_malformed = 0;      // sent garbled (malformed-ok)
};

class SimFirmware {
 public:
  // silent: hung (silent-after); booting: rebooting as the port opened (reset-on-open). Both say
  // nothing and lose what arrives, until silent-for or boot-for is up. halted: after kill().
  enum class State { running, silent, booting, halted, disconnected };

  explicit SimFirmware(SimConfig config);

  void boot(Micros now);  // "start" and the banner, as after a reset
  void receive(std::string_view bytes, Micros now);
  // The host opened the port. With reset-on-open the board reboots, as an Arduino on DTR.
  void port_opened(Micros now);
  void advance(Micros now);
  std::string take_output(Micros now);
  std::vector<std::string> take_executed() { return std::exchange(executed_, {}); }
  Micros next_wakeup() const;

  State state() const { return state_; }
  const SimStats& stats() const { return stats_; }

 private:
  struct Command {
    std::string text;                 // without line number, checksum and comment
    std::optional<long long> number;  // its N, for ADVANCED_OK
  };
  struct Heater {
    double temperature = 21, target = 0, rate = 1;
  };

  void say(std::string_view line, Micros now);
  void ok(const Command& c, Micros now);
  void send_ok(std::string line, long long command, Micros now);
  void read_commands(Micros now);
  void line_error(std::string_view what, Micros now);
  void request_resend(Micros now);
  bool rerequested(Micros now);
  bool held(Micros now);
  bool deaf() const { return state_ == State::silent || state_ == State::booting; }
  void wake(Micros now);
  void scan_emergency(std::string_view line, Micros now);
  // blocked: try again later; replied: it sent its own ok (M105); halt: M112 without the parser.
  enum class Outcome { blocked, done, replied, halt };
  Outcome execute(const Command& c, Micros now);
  bool move(const Command& c, Micros now);
  void after_executed(Outcome outcome, Micros now);
  void kill(std::string_view why, Micros now);
  void clear(Micros now);
  void reset(Micros now);
  void update_heaters(Micros now);
  void keepalive(Micros now);
  Micros busy_every() const;
  std::string temperature_report() const;
  double heat_scale() const;
  Micros scaled(double printer_seconds, double scale) const;

  SimConfig config_;
  State state_ = State::running;
  SimStats stats_;
  Wire in_, out_;
  std::string rx_;
  std::string incoming_;  // the line arriving, for the emergency parser
  std::deque<Command> queue_;
  long long last_n_ = 0;
  bool flushing_ = false;       // after a line error, until the rest of the line is discarded
  std::deque<Micros> planner_;  // end time of each queued move
  Micros planner_free_at_{0};
  Heater hotend_, bed_;
  Micros heaters_at_{0};
  // The command at the head of the queue, once started: when it may finish.
  bool head_started_ = false;
  Micros head_until_{0};
  bool heating_wait_ = false;
  bool abort_wait_ = false;  // M108
  Micros next_busy_{Micros::max()}, next_heat_report_{Micros::max()};
  Micros autoreport_every_{0}, next_autoreport_{Micros::max()};
  // Faults at a known moment: each fires once.
  Micros deaf_until_{0};  // silent or booting until then; Micros::max(): for ever
  bool rerequest_done_ = false;
  bool busy_done_ = false;
  Micros hold_until_{0};  // the head is held by busy-for until then; 0: not held
  // Modal state for moves.
  double pos_[4] = {0, 0, 0, 0};
  double feed_mm_s_ = 25;
  bool relative_ = false, relative_e_ = false;
  std::vector<std::string> executed_;
  std::mt19937_64 rng_;
};

}  // namespace salient::protocol::sim
