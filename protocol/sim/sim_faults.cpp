#include "protocol/sim/sim_faults.hpp"

#include <charconv>
#include <optional>
#include <stdexcept>
#include <string>

namespace salient::protocol::sim {
namespace {

constexpr double kMaxSeconds = 86400;  // a day: longer is a typo, and would overflow the clock

[[noreturn]] void bad(std::string_view key, const std::string& what) {
  throw std::invalid_argument("--faults: " + std::string(key) + " " + what);
}

template <typename T>
T number(std::string_view key, std::string_view value) {
  T v{};
  const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
  if (ec != std::errc() || ptr != value.data() + value.size())
    throw std::invalid_argument("--faults: " + std::string(key) + "=" + std::string(value) +
                                " is not a number");
  return v;
}

double probability(std::string_view key, std::string_view value) {
  // from_chars for double is in libstdc++ 11+, so this parses as the integers do.
  const double p = number<double>(key, value);
  if (!(p >= 0 && p <= 1)) bad(key, "must be between 0 and 1");
  return p;
}

long long count(std::string_view key, std::string_view value) {
  const long long n = number<long long>(key, value);
  if (n <= 0) bad(key, "must be a positive count of commands");
  return n;
}

// Written this way round so that NaN and infinity fail too.
double seconds(std::string_view key, std::string_view value, bool zero_allowed) {
  const double s = number<double>(key, value);
  if (!((zero_allowed ? s >= 0 : s > 0) && s <= kMaxSeconds))
    bad(key, std::string("must be a number of seconds, ") +
                 (zero_allowed ? "from 0 to 86400" : "more than 0 and at most 86400"));
  return s;
}

bool flag(std::string_view key, std::optional<std::string_view> value) {
  return !value || number<int>(key, *value) != 0;
}

void apply(SimFaults& f, std::string_view key, std::optional<std::string_view> value) {
  auto v = [&] {
    if (!value) bad(key, "needs a value (" + std::string(key) + "=…)");
    return *value;
  };
  if (key == "noise")
    f.noise = probability(key, v());
  else if (key == "drop-ok")
    f.drop_ok = probability(key, v());
  else if (key == "resend-without-ok")
    f.resend_without_ok = flag(key, value);
  else if (key == "disconnect-after")
    f.disconnect_after = count(key, v());
  else if (key == "reset-after")
    f.reset_after = count(key, v());
  else if (key == "thermal-runaway-at")
    f.thermal_runaway_at = count(key, v());
  else if (key == "silent-after")
    f.silent_after = count(key, v());
  else if (key == "silent-for")
    f.silent_for = seconds(key, v(), false);
  else if (key == "rerequest")
    f.rerequest = count(key, v());
  else if (key == "busy-for")
    f.busy_for = seconds(key, v(), false);
  else if (key == "busy-at")
    f.busy_at = count(key, v());
  else if (key == "malformed-ok")
    f.malformed_ok = count(key, v());
  else if (key == "reset-on-open")
    f.reset_on_open = flag(key, value);
  else if (key == "boot-for")
    f.boot_for = seconds(key, v(), true);
  else if (key == "seed")
    f.seed = number<std::uint64_t>(key, v());
  else
    throw std::invalid_argument("--faults: unknown fault '" + std::string(key) +
                                "' (known: noise, drop-ok, resend-without-ok, disconnect-after, reset-after, "
                                "thermal-runaway-at, silent-after, silent-for, rerequest, busy-for, busy-at, "
                                "malformed-ok, reset-on-open, boot-for, seed)");
}

}  // namespace

SimFaults parse_faults(std::string_view spec) {
  SimFaults f;
  bool boot_for_given = false;
  while (!spec.empty()) {
    const std::size_t comma = spec.find(',');
    const std::string_view item = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    const std::string_view key = item.substr(0, eq);
    apply(f, key, eq == std::string_view::npos ? std::nullopt : std::optional(item.substr(eq + 1)));
    boot_for_given |= key == "boot-for";
  }
  // A modifier alone would be ignored in silence: say so instead.
  if (f.silent_for > 0 && !f.silent_after) bad("silent-for", "needs silent-after=N (the hang it ends)");
  if (f.busy_at && f.busy_for <= 0) bad("busy-at", "needs busy-for=S (how long command N is held)");
  if (boot_for_given && !f.reset_on_open) bad("boot-for", "needs reset-on-open (the reboot it times)");
  return f;
}

std::string_view faults_help() {
  return R"(Faults, for --faults A=x,B,... (commands are counted from power-on, the host's M115 and M110
included: command N is line N of --log; seconds are wall-clock, whatever --time-scale):
  noise=P               a received line gets one byte changed, with probability P
  drop-ok=P             an ok is never sent, with probability P
  resend-without-ok     "Resend: N" comes without the ok that Marlin sends after it
  disconnect-after=N    after command N the cable is pulled (the simulator exits)
  reset-after=N         command N reboots the board ("start") instead of its ok
  thermal-runaway-at=N  command N ends in thermal runaway: kill(), halted
  silent-after=N        after command N's ok the board hangs: it says nothing, and what the host
                        sends is read and lost; the port stays open
  silent-for=S          with silent-after: the hang ends after S seconds (a stall), else never
  rerequest=N           command N, though intact, gets "Resend: N" + ok, once
  busy-for=S            the first G4, G28, M400, M109 or M190 is held S seconds before it runs,
                        with "echo:busy: processing" every 2 s
  busy-at=N             with busy-for: command N is the one held
  malformed-ok=N        command N's ok arrives garbled ("o", a NUL for the 'k'): no host sees it
  reset-on-open         the board reboots whenever the host opens the port (DTR, as an Arduino),
                        losing what it held and what arrives while it boots, then says "start"
  boot-for=S            with reset-on-open: how long it boots (default 0.5)
  seed=N                the random faults repeat for a seed (default 1)
)";
}

}  // namespace salient::protocol::sim
