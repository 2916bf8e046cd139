// Fuzz target for uploaded G-code (POST /api/files/local): check_printable and find_unsendable.
// Only Unprocessable (422) may come out; when the file is accepted, every command must frame, fit the
// firmware's line buffer and parse back to itself, as the print will send it.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "protocol/marlin/line_codec.hpp"
#include "server/common/domain_error.hpp"
#include "server/printers/print_file.hpp"

using namespace salient::server;
namespace marlin = salient::protocol::marlin;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string gcode(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> lines;  // as the printer splits a file
  for (std::size_t at = 0; at < gcode.size();) {
    std::size_t nl = gcode.find('\n', at);
    if (nl == std::string::npos) nl = gcode.size();
    std::string line = gcode.substr(at, nl - at);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(std::move(line));
    at = nl + 1;
  }
  const auto bad = marlin::find_unsendable(lines);
  long long commands = 0;
  try {
    commands = check_printable("fuzz.gcode", gcode);
  } catch (const DomainError& e) {
    if (e.kind() != ErrorKind::unprocessable) std::abort();
    if (e.code() == "not_gcode" && !bad) std::abort();
    return 0;
  }
  if (bad) std::abort();  // accepted a line the firmware cannot take
  const auto round_trip = [](std::uint64_t number, const std::string& command) {
    const std::string framed = marlin::frame(number, command);
    if (framed.size() > 96) std::abort();  // Marlin's MAX_CMD_SIZE
    marlin::FrameError error;
    const marlin::FramedLine back = marlin::parse_frame(framed, error);
    if (error != marlin::FrameError::none || back.number != number || back.command != command) std::abort();
  };
  long long n = 0;
  std::string longest;
  for (const std::string& line : lines) {
    std::string command = marlin::strip_comment(line);
    if (command.empty()) continue;
    round_trip(static_cast<std::uint64_t>(++n), command);
    if (command.size() > longest.size()) longest = std::move(command);
  }
  round_trip(9999999, longest);  // the longest command still fits with a seven-digit line number
  if (n != commands) std::abort();
  return 0;
}
