// SailfishFirmware: a MightyBoard running Sailfish 7.7 (a Replicator 2X) as a pure state machine:
// bytes and time in; reply bytes out, and the log of every action it executed, in order. The
// driver (salient-sim over a pseudo-terminal, or a test) moves the bytes and keeps the clock.
//
// What it models, after Sailfish's Host.cc and Command.cc (firmware/src/MightyBoard/Motherboard):
// packets read one at a time with the 200 ms packet timeout; one reply per packet (80 for a byte
// outside a packet, 83 bad CRC, 84 length over 32, 85 unknown query, 8C timeout); the queries
// (0, 2, 3, 7, 8, 10, 11, 17, 21, 22, 23, 24, 27); a 512-byte command ring that takes an action
// only when all of it fits (else 82, not queued) and runs actions one after another at their
// real durations, an action leaving the ring as it starts; an unknown action id that stalls the
// ring for ever, as on the board; heaters that ramp, so that waits (135, 141) hold the ring; the
// pause toggle; resets that leave the board deaf ~1 s; and the faults of sailfish_faults.hpp.
//
// Where we depart from the board (the shared host contract, which the host session relies on):
// build stats' line counts every action started since power-on or reset (Command.cc counts each
// action as it leaves the ring too, but zeroes the count at 153 build start, and Host.cc reports
// the last build's count once a build is over); the error replies 80/83/84/8C are sent (Host.cc
// has them commented out: a real host sees a timeout); 8B answers every packet after a heater
// fault (Host.cc sends one 89 first); queries 3 and 7 clear without a reset (Host.cc treats 3, 7
// and 17 alike: stop the build, or reset when not building); a wait for a button (148) is
// pressed at once; one move runs at a time (the board's 16-move planner is not modelled: an
// action leaves the ring as it starts).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/s3g_codes.hpp"
#include "protocol/sim/sailfish_faults.hpp"
#include "protocol/sim/wire.hpp"

namespace salient::protocol::sim {

struct SailfishConfig {
  double baud = 0;                          // bits per second on the wire, 10 per byte; 0: no limit
  double time_scale = 0;                    // wall seconds per printer second for motion; 0: instant
  double heat_time_scale = -1;              // the same for heaters; negative: as time_scale
  std::size_t ring_bytes = 512;             // COMMAND_BUFFER_SIZE
  Micros packet_timeout{200000};            // HOST_PACKET_TIMEOUT_MS
  Micros reset_for{1000000};                // wall time the board is deaf after a reset
  Micros cancel_reset_after{1000000};       // cancel: resets this long after, if no packet came
  double hotend_rate = 3, bed_rate = 1;     // °C/s heating
  double hotend_cool = 1, bed_cool = 0.25;  // °C/s cooling, slower
  double ambient = 21;
  double ready_band = 2;  // °C: a heater within this of its target is ready
  // Steps per mm (GPX's r2x), for homing times; the positions that homing and 144 set (plausible
  // r2x home offsets: a real board keeps its own in EEPROM).
  std::array<double, 5> steps_per_mm{88.888889, 88.888889, 400, 96.2752018703, 96.2752018703};
  std::array<std::int32_t, 5> home_steps{13511, 6533, 0, 0, 0};
  std::array<double, 3> travel_mm{246, 152, 155};  // homing from an unknown position
  std::uint16_t firmware_version = 707, internal_version = 0;
  // 80, 83, 84 and 8C are sent, as the shared host contract has it; false: silence instead, as
  // Sailfish 7.7 really does.
  bool error_replies = true;
  SailfishFaults faults;
};

struct SailfishStats {
  long long executed = 0;           // actions started (the --log's lines)
  long long packets_received = 0;   // whole packets with a good CRC
  long long packets_corrupted = 0;  // by the noise fault
  // Taken although the host never sent it as such: noise that shortened a length and still passed
  // the CRC (1 in 256), or a start byte inside the host's bytes. s3g cannot tell; a real board
  // runs it too. Also counted in packets_received.
  long long false_packets = 0;
  long long crc_errors = 0;        // 83 sent
  long long length_errors = 0;     // 84 sent
  long long packet_timeouts = 0;   // 8C sent
  long long stray_bytes = 0;       // 80 sent
  long long unsupported = 0;       // 85 sent
  long long buffer_full_sent = 0;  // 82 sent, storms included
  long long storm_refusals = 0;    // of those, refused by full-storm although they fit
  long long replies_dropped = 0;
  long long replies_corrupted = 0;
  long long resets = 0;
  long long bytes_ignored = 0;  // arrived while resetting or hung, and lost
};

class SailfishFirmware {
 public:
  // resetting: deaf for reset_for; heater_shutdown: 8B to everything; silent: hung for ever.
  enum class State { ready, resetting, heater_shutdown, silent };
  // Query 24's build state, as Sailfish numbers it.
  enum class Build : std::uint8_t { none = 0, running = 1, finished = 2, paused = 3, cancelled = 4 };

  explicit SailfishFirmware(SailfishConfig config);

  // Times are the driver's clock; it never goes back.
  // Bytes the host wrote at `now`: they reach the board at the wire's rate (config baud).
  void receive(std::string_view bytes, Micros now);
  // Reads what has arrived, answers it, runs the ring: everything due by `now`.
  void advance(Micros now);
  // Reply bytes that have reached the host by `now`.
  std::string take_output(Micros now);
  // Each executed action's payload in lowercase hex, in order (the --log's lines).
  std::vector<std::string> take_executed() { return std::exchange(executed_, {}); }
  // When advance() next has something to do; Micros::max(): nothing until bytes come.
  Micros next_wakeup() const;

  State state() const { return state_; }
  Build build() const { return build_; }
  const SailfishStats& stats() const { return stats_; }
  std::size_t ring_used() const { return ring_.size(); }
  double hotend_temperature() const { return hotend_.temperature; }
  double bed_temperature() const { return bed_.temperature; }
  const std::array<std::int32_t, 5>& position() const { return pos_; }

 private:
  struct Heater {
    double temperature = 21, target = 0, rate = 1, cool = 1;
  };
  enum class Wait { none, hotend, bed };

  void feed(std::uint8_t byte, Micros now);
  std::uint8_t corrupt_incoming(std::uint8_t byte);
  void handle_packet(const std::string& payload, Micros now);
  std::string answer(const std::string& payload, Micros now);
  std::string query(const std::string& payload, Micros now);
  std::string tool_query(const std::string& payload) const;
  std::string queue_action(const std::string& payload);
  void reply(std::string payload, Micros now);
  void link_error(s3g::Reply r, Micros now);
  void run(Micros now);
  bool finish_current(Micros now);
  void start(const std::string& action, Micros now);
  Micros move(const std::string& a);  // sets the target; its duration
  Micros home_time(const std::string& a) const;
  void after_started(Micros now);
  void stop_motion(Micros now);
  void heaters_off();
  void reset(Micros now);
  void cancel(Micros now);
  void update_heaters(Micros now);
  bool heater_ready(const Heater& h) const;
  Micros heater_ready_at(const Heater& h, Micros now) const;
  double heat_scale() const;
  Micros scaled(double printer_seconds, double scale) const;
  bool chance(double p);

  SailfishConfig config_;
  State state_ = State::ready;
  Build build_ = Build::none;
  SailfishStats stats_;
  Wire in_, out_;
  s3g::PacketDecoder decoder_;
  Micros packet_started_{0};
  // The noise fault follows the host's framing, not the decoder's: which byte of the packet
  // the host sent is next, how long that packet is, and which of its bytes gets changed.
  int host_at_ = -1, host_length_ = 0, corrupt_at_ = -1;
  // The byte being fed: its place in the host's packet (-1: none), whether noise changed it,
  // whether it is the host packet's last; and whether the decoder's packet is the host's so far.
  int byte_host_at_ = -1;
  bool byte_corrupted_ = false, byte_ends_packet_ = false, packet_true_ = false;
  std::string ring_;  // the command ring's bytes, head first
  // The action running, once started: when it ends (Micros::max() while a wait holds it).
  bool running_ = false;
  Micros until_{0};
  Wait wait_ = Wait::none;
  Micros wait_deadline_{0};
  bool paused_ = false;
  long long line_ = 0;  // actions started since power-on or reset
  Micros build_started_{0}, last_build_time_{0};
  int percent_ = 0;
  Heater hotend_, bed_;
  Micros heaters_at_{0};
  bool fan_ = false;
  std::array<std::int32_t, 5> pos_{};
  std::uint16_t endstops_ = 0;  // bit 2i: axis i at its min endstop, 2i+1: at its max
  std::uint8_t homed_ = 0;      // axes whose position is known from homing
  Micros deaf_until_{0};
  bool cancel_pending_ = false;  // the next packet gets 89
  Micros cancel_reset_at_{Micros::max()};
  int storm_left_ = 0;  // full-storm: refusals left in this burst
  bool storm_ended_ = false;
  std::vector<std::string> executed_;
  std::mt19937_64 rng_;
};

}  // namespace salient::protocol::sim
