// StreamDemand: how fast a G-code file's commands must reach the printer, against what a serial
// link carries — a file denser than its link starves the firmware's planner (stutter, blobs).
#pragma once

#include <vector>

#include "core/gcode/time_estimator.hpp"

namespace salient::core {

// The link, as we model it: 8N1 framing (10 bits a byte), each command sent as Marlin numbers it
// ("N123 G1 X1 Y2 E0.1*45\n") and answered "ok\n" before the next is sent (ping-pong, as most hosts
// stream), with no USB or parsing latency. So a command costs (framed bytes + 3) · 10 / baud
// seconds, and the figure is an upper bound on what a real link carries.
struct StreamDemand {
  double peak_commands_per_second = 0;  // the most commands starting within any one second
  double peak_at_seconds = 0;           // when that second begins, s into the file's motion
  double mean_framed_bytes = 0;         // of those commands, as sent (line number and checksum too)
  int baud = 0;
  double link_commands_per_second = 0;  // what the link carries at that length

  bool starves() const { return peak_commands_per_second > link_commands_per_second; }
};

inline constexpr int ok_reply_bytes = 3;  // "ok\n"

// From the estimator's per-command timings (estimate_gcode's `commands`), in file order: each
// command starts when the ones before it have run. Commands are numbered from 1 (after M110 N0).
StreamDemand stream_demand(const std::vector<CommandTiming>& commands, int baud);

}  // namespace salient::core
