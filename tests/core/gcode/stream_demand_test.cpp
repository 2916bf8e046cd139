// The stream a file needs: the busiest second's commands, framed as Marlin numbers them, against
// a ping-pong link's capacity at a baud rate.
#include "core/gcode/stream_demand.hpp"

#include <doctest/doctest.h>

#include <string>

using namespace salient::core;

namespace {

CommandTiming command(const std::string& text, double seconds) {
  CommandTiming c;
  c.seconds = seconds;
  c.bytes = static_cast<std::uint32_t>(text.size());
  for (char ch : text) c.xor_sum ^= static_cast<std::uint8_t>(ch);
  return c;
}

}  // namespace

TEST_CASE("framed length and capacity: N<n> <text>*<sum>\\n, each answered ok") {
  // "N1 G28*18\n": 10 bytes (the checksum of "N1 G28" is 18), plus "ok\n" back: 13 bytes of 10 bits.
  const StreamDemand d = stream_demand({command("G28", 0)}, 115200);
  CHECK(d.peak_commands_per_second == 1);
  CHECK(d.mean_framed_bytes == 10);
  CHECK(d.link_commands_per_second == doctest::Approx(11520.0 / 13));
  CHECK_FALSE(d.starves());
}

TEST_CASE("the busiest second: commands starting within any one second, wherever it falls") {
  std::vector<CommandTiming> c;
  for (int i = 0; i < 100; ++i) c.push_back(command("G1 X1 Y1 E0.1", 0.1));    // 10 a second, 10 s
  for (int i = 0; i < 500; ++i) c.push_back(command("G1 X1 Y1 E0.1", 0.002));  // 500 a second, 1 s
  for (int i = 0; i < 100; ++i) c.push_back(command("G1 X1 Y1 E0.1", 0.1));
  const StreamDemand d = stream_demand(c, 115200);
  // From the burst's start the next second holds the 500 and 9 or 10 of the slow ones after it.
  CHECK(d.peak_commands_per_second >= 500);
  CHECK(d.peak_commands_per_second <= 511);
  CHECK(d.peak_at_seconds == doctest::Approx(10).epsilon(0.01));
  CHECK(d.starves());  // ~25-byte lines: 400 a second at most
  // The same at 10× the baud rate fits.
  CHECK_FALSE(stream_demand(c, 1152000).starves());
  // Zero-time commands (temperatures, fan) count where they stand.
  std::vector<CommandTiming> settings(50, command("M104 S200", 0));
  CHECK(stream_demand(settings, 115200).peak_commands_per_second == 50);
  CHECK(stream_demand({}, 115200).peak_commands_per_second == 0);
  CHECK_FALSE(stream_demand({}, 115200).starves());
}

TEST_CASE("peak is monotonic: slowing every command never raises it") {
  std::vector<CommandTiming> c;
  for (int i = 0; i < 2000; ++i) c.push_back(command("G1 X10.123 Y20.456 E0.01234", 0.001 * (1 + i % 7)));
  double last = 1e300;
  for (double slow : {1.0, 1.5, 2.0, 4.0}) {
    std::vector<CommandTiming> s = c;
    for (CommandTiming& t : s) t.seconds *= slow;
    const double peak = stream_demand(s, 115200).peak_commands_per_second;
    CHECK(peak <= last);
    last = peak;
  }
}
