// Fuzz target for Marlin line framing: parsing any line must not crash, and framing what
// parsed must parse back to the same number and command.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "protocol/marlin/line_codec.hpp"

using namespace salient::protocol::marlin;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size < 4096 ? size : 4096);
  FrameError error;
  const FramedLine parsed = parse_frame(line, error);
  const std::string command = strip_comment(line);
  if (command.find('*') == std::string::npos && command.find('\n') == std::string::npos &&
      command.find('\r') == std::string::npos && !command.empty()) {
    FrameError again;
    const FramedLine round = parse_frame(frame(7, command), again);
    if (again != FrameError::none || round.number != 7u || round.command != command) std::abort();
  }
  (void)parsed;
  return 0;
}
