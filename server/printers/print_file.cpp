#include "server/printers/print_file.hpp"

#include "protocol/marlin/line_codec.hpp"
#include "server/common/domain_error.hpp"

namespace salient::server {

std::vector<std::string> gcode_lines(const std::string& gcode) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < gcode.size()) {
    std::size_t nl = gcode.find('\n', start);
    if (nl == std::string::npos) nl = gcode.size();
    std::string line = gcode.substr(start, nl - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(std::move(line));
    start = nl + 1;
  }
  return lines;
}

long long check_printable(const std::string& name, const std::string& gcode) {
  const std::vector<std::string> lines = gcode_lines(gcode);
  // A line the firmware cannot take would stall the print halfway: refused before it starts.
  if (auto bad = protocol::marlin::find_unsendable(lines))
    throw Unprocessable("not_gcode",
                        name + " line " + std::to_string(bad->line) + " cannot be sent: " + bad->why);
  long long commands = 0;
  for (const std::string& line : lines)
    if (!protocol::marlin::strip_comment(line).empty()) ++commands;
  if (commands == 0)
    throw Unprocessable("no_commands", name + " holds no G-code commands (only comments or blank lines)");
  return commands;
}

}  // namespace salient::server
