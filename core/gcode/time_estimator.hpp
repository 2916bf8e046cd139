// Print-time estimate of any G-code file: trapezoidal acceleration per move with junction
// speeds limited by per-axis jerk, planned forward and backward as Marlin's planner does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/progress.hpp"

namespace salient::core {

struct MachineLimits {
  double acceleration = 1000;                                  // mm/s², extruding moves (M204 P / S)
  double travel_acceleration = 1000;                           // mm/s², moves without extrusion (M204 T)
  double retract_acceleration = 1000;                          // mm/s², extruder-only moves (M204 R)
  double jerk[4] = {10, 10, 0.4, 5};                           // mm/s, X Y Z E (M205 X Y Z E)
  double max_feedrate[4] = {500, 500, 12, 120};                // mm/s (M203)
  double max_axis_acceleration[4] = {9000, 9000, 500, 10000};  // mm/s² (M201)
};

struct GcodeEstimate {
  double seconds = 0;             // motion and dwells; heating waits are not included
  std::size_t heating_waits = 0;  // M109 / M190 / M116 seen
  double filament_mm = 0;         // extruded length of filament (retractions netted out)
  std::size_t moves = 0;
  std::size_t lines = 0;
  // Split at ;LAYER_CHANGE / ;LAYER: comments (one layer if none); what comes before the first
  // mark (the start code) counts with the first layer.
  std::vector<double> layer_seconds;
  // OctoPrint's printing area: the box of the extruding moves' ends (an arc's bulge past its ends
  // is left out), mm; only when `printed`.
  bool printed = false;
  double printing_min[3] = {0, 0, 0}, printing_max[3] = {0, 0, 0};
};

// One command of a file (a line with a G, M or T word), as the planner times it and a host sends it.
struct CommandTiming {
  double seconds = 0;        // how long it keeps the machine busy: a move's planned time, a dwell
  std::uint32_t bytes = 0;   // its text without comment and surrounding blanks
  std::uint8_t xor_sum = 0;  // XOR of those bytes (Marlin's checksum covers them)
};

// Throws InputError "SOURCE:LINE: …" for a malformed word (such as "X1.2.3"). Unknown commands
// are skipped, as firmware does. Limits set in the file (M201/M203/M204/M205) override `limits`.
// Arcs (G2/G3 with I J) take their length along the arc and meet their neighbours along their
// tangents. With `commands`, each command's timing is appended to it, in file order. A `cancel`
// set stops it (Cancelled) within a few thousand lines: a long print's file takes seconds.
GcodeEstimate estimate_gcode(std::string_view text, const std::string& source, MachineLimits limits = {},
                             std::vector<CommandTiming>* commands = nullptr,
                             const CancelToken* cancel = nullptr);

}  // namespace salient::core
