// stream_demand: a sliding one-second window over the commands' start times (two pointers), the
// framed length of each command from its text's length and XOR (so the exact checksum digits).
#include "core/gcode/stream_demand.hpp"

#include <string>

namespace salient::core {
namespace {

std::size_t digits(std::size_t n) {
  std::size_t d = 1;
  while (n >= 10) n /= 10, ++d;
  return d;
}

// "N<n> <text>*<sum>\n": the checksum is the XOR of every byte before '*'.
std::size_t framed_bytes(const CommandTiming& c, std::size_t n) {
  std::uint8_t sum = c.xor_sum ^ static_cast<std::uint8_t>('N') ^ static_cast<std::uint8_t>(' ');
  for (char ch : std::to_string(n)) sum ^= static_cast<std::uint8_t>(ch);
  return 1 + digits(n) + 1 + c.bytes + 1 + digits(sum) + 1;
}

}  // namespace

StreamDemand stream_demand(const std::vector<CommandTiming>& commands, int baud) {
  StreamDemand out;
  out.baud = baud;
  const std::size_t n = commands.size();
  std::vector<double> start(n + 1, 0);
  std::vector<double> bytes(n + 1, 0);  // prefix sums of framed bytes
  for (std::size_t i = 0; i < n; ++i) {
    start[i + 1] = start[i] + commands[i].seconds;
    bytes[i + 1] = bytes[i] + static_cast<double>(framed_bytes(commands[i], i + 1));
  }
  std::size_t best_first = 0, best_count = 0;
  for (std::size_t first = 0, end = 0; first < n; ++first) {
    if (end < first) end = first;
    while (end < n && start[end] < start[first] + 1.0) ++end;  // commands starting in [t, t + 1 s)
    if (end - first > best_count) best_count = end - first, best_first = first;
  }
  out.peak_commands_per_second = static_cast<double>(best_count);
  out.peak_at_seconds = start[best_first];
  if (best_count > 0)
    out.mean_framed_bytes = (bytes[best_first + best_count] - bytes[best_first]) / best_count;
  if (baud > 0 && out.mean_framed_bytes > 0)
    out.link_commands_per_second = baud / 10.0 / (out.mean_framed_bytes + ok_reply_bytes);
  return out;
}

}  // namespace salient::core
