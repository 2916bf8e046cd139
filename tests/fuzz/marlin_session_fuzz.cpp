// Fuzz target for the Marlin host session: arbitrary bytes from the "firmware", cut into reads,
// with time passing. It must not crash, every line it sends must frame correctly, and it must
// never count more commands done than it was given.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/marlin/marlin_session.hpp"

using namespace salient::protocol::marlin;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SessionConfig config;
  config.reply_timeout = std::chrono::milliseconds(50);
  MarlinSession s(config);
  s.begin({"G28", "G1 X10 Y10 F3000", "M104 S200", "G1 X20 E1", "M105"}, Millis(0));
  std::size_t at = 0;
  long long now = 0;
  while (at < size) {
    const std::size_t chunk = 1 + data[at] % 32;
    const std::string_view bytes(reinterpret_cast<const char*>(data) + at + 1, std::min(chunk, size - at - 1));
    at += 1 + bytes.size();
    now += data[at - 1] % 100;
    s.on_receive(bytes, Millis(now));
    s.on_tick(Millis(now));
    std::istringstream out(s.take_output());
    for (std::string line; std::getline(out, line);) {
      if (line == "M112") continue;
      FrameError e;
      parse_frame(line, e);
      if (e != FrameError::none) std::abort();
    }
    s.take_events();
    if (s.commands_done() > s.commands_total()) std::abort();
  }
  return 0;
}
