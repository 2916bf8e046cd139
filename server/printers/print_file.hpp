// The G-code a printer prints, checked when a print is asked for: a file the firmware cannot take
// is refused before it starts, not halfway.
#pragma once

#include <memory>
#include <string>

#include "protocol/gcode/program.hpp"
#include "server/config/daemon_config.hpp"

namespace salient::server {

// `gcode` as the program to stream; Unprocessable (422) when it has no command, or a line that
// cannot be sent (too long, binary, not ASCII, or a line number or M110: the host numbers the
// lines), named with its line number. For a printer that
// speaks s3g also a command the x3g translator would skip (a Marlin-only code: the file was not
// sliced for this machine), so that nothing of a print is silently left out.
std::shared_ptr<const protocol::Program> printable_program(const std::string& name, const std::string& gcode,
                                                           const PrinterConfig* printer = nullptr);

// The number of commands in `gcode`, refused as printable_program refuses it.
inline long long check_printable(const std::string& name, const std::string& gcode) {
  return static_cast<long long>(printable_program(name, gcode)->size());
}

}  // namespace salient::server
