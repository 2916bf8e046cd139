#include "protocol/sim/sailfish_faults.hpp"

#include <charconv>
#include <optional>
#include <stdexcept>

namespace salient::protocol::sim {
namespace {

[[noreturn]] void bad(std::string_view key, const std::string& what) {
  throw std::invalid_argument("--faults: " + std::string(key) + " " + what);
}

template <typename T>
T number(std::string_view key, std::string_view value) {
  T v{};
  const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
  if (value.empty() || ec != std::errc() || ptr != value.data() + value.size())
    throw std::invalid_argument("--faults: " + std::string(key) + "=" + std::string(value) +
                                " is not a number");
  return v;
}

double probability(std::string_view key, std::string_view value) {
  const double p = number<double>(key, value);
  if (!(p >= 0 && p <= 1)) bad(key, "must be between 0 and 1");  // NaN fails too
  return p;
}

long long count(std::string_view key, std::string_view value) {
  const long long n = number<long long>(key, value);
  if (n <= 0) bad(key, "must be a positive count of actions");
  return n;
}

}  // namespace

SailfishFaults parse_sailfish_faults(std::string_view spec) {
  SailfishFaults f;
  while (!spec.empty()) {
    const std::size_t comma = spec.find(',');
    const std::string_view item = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    const std::string_view key = item.substr(0, eq);
    if (eq == std::string_view::npos) bad(key, "needs a value (" + std::string(key) + "=…)");
    const std::string_view v = item.substr(eq + 1);
    if (key == "noise")
      f.noise = probability(key, v);
    else if (key == "reply-noise")
      f.reply_noise = probability(key, v);
    else if (key == "drop-reply")
      f.drop_reply = probability(key, v);
    else if (key == "full-storm")
      f.full_storm = probability(key, v);
    else if (key == "reset-at")
      f.reset_at = count(key, v);
    else if (key == "cancel-at")
      f.cancel_at = count(key, v);
    else if (key == "heater-fault-at")
      f.heater_fault_at = count(key, v);
    else if (key == "silent-after")
      f.silent_after = count(key, v);
    else if (key == "seed")
      f.seed = number<std::uint64_t>(key, v);
    else
      throw std::invalid_argument("--faults: unknown fault '" + std::string(key) +
                                  "' for sailfish (known: noise, reply-noise, drop-reply, full-storm, "
                                  "reset-at, cancel-at, heater-fault-at, silent-after, seed)");
  }
  return f;
}

std::string_view sailfish_faults_help() {
  return R"(Faults with --firmware sailfish (actions are counted from power-on: action N is line N of
--log; each fault at a known moment fires once, as action N starts):
  noise=P               a received packet gets one byte changed, with probability P: the board
                        answers 83 (CRC), 84 (length), 8C (timeout) or 80 (stray bytes)
  reply-noise=P         a reply gets one byte changed on the way back, with probability P
  drop-reply=P          a packet is acted on and its reply lost, with probability P
  full-storm=P          an action that fits starts, with probability P, a burst of 1 to 20
                        actions refused with 82 (buffer full) although they fit
  reset-at=N            after action N the board resets: ring lost, deaf for ~1 s, heaters off,
                        position unknown, build state 0, line 0
  cancel-at=N           after action N the user cancels on the LCD: the ring is dropped, heaters
                        off, the next packet gets 89 (not run), then the board resets
  heater-fault-at=N     after action N the heaters shut down: every packet from then on gets 8B
  silent-after=N        after action N the board hangs: no reply, no execution, ever
  seed=N                the random faults repeat for a seed (default 1)
)";
}

}  // namespace salient::protocol::sim
