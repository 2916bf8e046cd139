// resume_prelude: what to send before command `resume_from` of a print so that a printer that lost
// the link (and maybe its state) carries on where the file left it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "protocol/gcode/program.hpp"

namespace salient::protocol::marlin {

// Temperatures (set, then waited for), units and positioning modes, the fan, the head back over
// its last X Y, 1 mm of filament re-primed there, the extruder position (G92 E), the head down
// to its last Z, and the feed rate, as the first
// `resume_from` commands of `program` left them.
std::vector<std::string> resume_prelude(const Program& program, std::size_t resume_from);

}  // namespace salient::protocol::marlin
