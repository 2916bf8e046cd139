#include "protocol/sim/sim_faults.hpp"

#include <charconv>
#include <stdexcept>
#include <string>

namespace salient::protocol::sim {
namespace {

template <typename T>
T number(std::string_view key, std::string_view value) {
  T v{};
  const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
  if (ec != std::errc() || ptr != value.data() + value.size())
    throw std::invalid_argument("--faults: " + std::string(key) + "=" + std::string(value) + " is not a number");
  return v;
}

double probability(std::string_view key, std::string_view value) {
  // from_chars for double is in libstdc++ 11+, so this parses as the integers do.
  const double p = number<double>(key, value);
  if (!(p >= 0 && p <= 1)) throw std::invalid_argument("--faults: " + std::string(key) + " must be between 0 and 1");
  return p;
}

long long count(std::string_view key, std::string_view value) {
  const long long n = number<long long>(key, value);
  if (n <= 0) throw std::invalid_argument("--faults: " + std::string(key) + " must be a positive count of commands");
  return n;
}

}  // namespace

SimFaults parse_faults(std::string_view spec) {
  SimFaults f;
  while (!spec.empty()) {
    const std::size_t comma = spec.find(',');
    const std::string_view item = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    const std::string_view key = item.substr(0, eq);
    const std::string_view value = eq == std::string_view::npos ? std::string_view{} : item.substr(eq + 1);
    const bool has_value = eq != std::string_view::npos;
    if (key != "resend-without-ok" && !has_value)
      throw std::invalid_argument("--faults: " + std::string(key) + " needs a value (" + std::string(key) + "=…)");
    if (key == "noise") f.noise = probability(key, value);
    else if (key == "drop-ok") f.drop_ok = probability(key, value);
    else if (key == "resend-without-ok") f.resend_without_ok = !has_value || number<int>(key, value) != 0;
    else if (key == "disconnect-after") f.disconnect_after = count(key, value);
    else if (key == "reset-after") f.reset_after = count(key, value);
    else if (key == "thermal-runaway-at") f.thermal_runaway_at = count(key, value);
    else if (key == "seed") f.seed = number<std::uint64_t>(key, value);
    else
      throw std::invalid_argument("--faults: unknown fault '" + std::string(key) +
                                  "' (known: noise, drop-ok, resend-without-ok, disconnect-after, reset-after, "
                                  "thermal-runaway-at, seed)");
  }
  return f;
}

}  // namespace salient::protocol::sim
