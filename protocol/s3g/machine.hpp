// Machine: what the G-code → s3g translator needs to know of a printer — steps per mm, feed-rate
// limits, homing speeds and endstops per axis, which tool heats the bed. The values are GPX 2.6.8's
// built-in definitions (markwal/GPX src/shared/std_machines.h), so that our x3g matches gpx's.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace salient::protocol::s3g {

struct Axis {
  double max_feedrate = 0;   // mm/min
  double home_feedrate = 0;  // mm/min
  double length = 0;         // mm of travel
  double steps_per_mm = 0;
  bool endstop_max = false;  // homes to its maximum (G162), else to its minimum (G161)
};

struct Extruder {
  double max_feedrate = 0;  // mm/min of filament
  double steps_per_mm = 0;
  bool heats_bed = false;  // the bed's heater answers to this tool (GPX: has_heated_build_platform)
};

struct Machine {
  std::string id;    // "r2x": gpx's -m name
  std::string name;  // "Replicator 2X"
  Axis x, y, z;
  Extruder a, b;
  double nozzle_diameter = 0.4;  // mm
  unsigned extruder_count = 1;   // tools T0…; M18/M84 without axes switch off XYZ and these
  unsigned timeout = 20;         // s: the homing commands' timeout
};

// A built-in machine by gpx's id, or nullptr.
const Machine* find_machine(std::string_view id);
// The ids find_machine knows, in table order.
std::vector<std::string> machine_ids();

}  // namespace salient::protocol::s3g
