// ExtrusionCounter: the filament a print has pushed, followed command by command as they are
// confirmed — what a history keeps per print (Moonraker's filament_used) and what a cancelled or
// interrupted print used up to where it stopped. Net of retractions: a retract and its prime
// cancel out. Absolute (M82) and relative (M83, G91) extrusion and G92 E resets are followed;
// so is the nozzle's height on the way (OctoPrint's currentZ), which needs the same walk.
#pragma once

#include <cstddef>
#include <optional>

#include "protocol/gcode/program.hpp"

namespace salient::protocol::marlin {

class ExtrusionCounter {
 public:
  explicit ExtrusionCounter(const Program& program) : program_(&program) {}
  // Counts the commands before `end` (not past the program) from where it stood; it moves only
  // forward (a smaller `end` counts nothing). Returns the filament these commands pushed, in mm.
  double advance_to(std::size_t end);
  // A resumed print counts from its first new command: what came before sets the state only.
  void skip_to(std::size_t end);
  double extruded_mm() const { return extruded_; }
  std::optional<double> z_mm() const { return z_; }  // none before the file sets one

 private:
  void step(const std::string& command, bool count);
  const Program* program_;  // not owned: it outlives the counter
  std::size_t next_ = 0;
  double e_ = 0, extruded_ = 0;
  std::optional<double> z_;
  bool relative_ = false, relative_e_ = false, inches_ = false;
};

}  // namespace salient::protocol::marlin
