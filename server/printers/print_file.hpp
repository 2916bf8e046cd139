// The G-code a printer prints: checked when a print is asked for (so that a file the firmware
// cannot take is refused before it starts, not halfway), and split into lines to stream.
#pragma once

#include <string>
#include <vector>

namespace salient::server {

// The number of commands in `gcode`; Unprocessable (422) when it has none, or a line that cannot
// be sent (too long, binary, not ASCII), named with its line number.
long long check_printable(const std::string& name, const std::string& gcode);

// `gcode`'s lines, without their line ends ("\n" or "\r\n").
std::vector<std::string> gcode_lines(const std::string& gcode);

}  // namespace salient::server
