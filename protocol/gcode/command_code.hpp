// CommandCode: which command a G-code line is ("G28", "M110", "G38.2"), read as Marlin's
// GCodeParser reads it, and the classes of command the host treats specially.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace salient::protocol {

struct CommandCode {
  char letter = 0;   // 'G', 'M' or 'T', upper case
  int number = 0;    // 28 in "G28"
  int sub = -1;      // 2 in "G38.2"; -1 when absent
  std::string text;  // as written for a person: "G28", "G38.2"
};

// The code of a command (comment stripped, no line number): Marlin upper-cases the letter and
// reads leading zeros ("g028" is G28) and a code glued to its words ("G1X10"). Absent when the
// command starts with no G, M or T code.
std::optional<CommandCode> command_code(std::string_view command);

// Commands that move the print head or bed, home, probe or redefine the position (G0–G3, G28,
// G29, G92, …) or release the motors (M18, M84): in the middle of a print each ruins it, which is
// why OctoPrint refuses jogging and homing while printing.
bool moves_or_homes(const CommandCode& code);

}  // namespace salient::protocol
