// CommandCode (Marlin 2.1 gcode/parser.cpp: GCodeParser::parse reads the letter, then digits,
// then an optional '.' subcode).
#include "protocol/gcode/command_code.hpp"

#include <algorithm>
#include <iterator>

namespace salient::protocol {
namespace {

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

}  // namespace

std::optional<CommandCode> command_code(std::string_view c) {
  while (!c.empty() && (c.front() == ' ' || c.front() == '\t')) c.remove_prefix(1);
  if (c.size() < 2) return std::nullopt;
  const char letter = static_cast<char>(c[0] >= 'a' && c[0] <= 'z' ? c[0] - 'a' + 'A' : c[0]);
  if ((letter != 'G' && letter != 'M' && letter != 'T') || !is_digit(c[1])) return std::nullopt;
  CommandCode out;
  out.letter = letter;
  std::size_t i = 1;
  for (; i < c.size() && is_digit(c[i]); ++i) out.number = std::min(out.number * 10 + (c[i] - '0'), 1000000);
  if (i + 1 < c.size() && c[i] == '.' && is_digit(c[i + 1])) out.sub = c[i + 1] - '0';
  out.text = std::string(1, letter) + std::to_string(out.number) +
             (out.sub >= 0 ? "." + std::to_string(out.sub) : "");
  return out;
}

bool moves_or_homes(const CommandCode& code) {
  // G0–G3 moves and arcs, G5 Bézier, G6 direct stepper move, G12 nozzle clean, G26 mesh test,
  // G27 park, G28 home, G29 bed levelling, G30 single probe, G33 delta calibration, G34/G35 gantry
  // and screw alignment, G38 probe to target, G42 move to mesh point, G61 return to a saved
  // position, G76 probe temperature calibration, G92 set position, G425 backlash calibration;
  // M18/M84 release the motors, M48 probe repeatability test.
  static constexpr int g[] = {0, 1, 2, 3, 5, 6, 12, 26, 27, 28, 29, 30, 33, 34, 35, 38, 42, 61, 76, 92, 425};
  static constexpr int m[] = {18, 48, 84};
  if (code.letter == 'G') return std::find(std::begin(g), std::end(g), code.number) != std::end(g);
  if (code.letter == 'M') return std::find(std::begin(m), std::end(m), code.number) != std::end(m);
  return false;
}

}  // namespace salient::protocol
