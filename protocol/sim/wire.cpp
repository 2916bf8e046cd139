#include "protocol/sim/wire.hpp"

#include <algorithm>
#include <cmath>

namespace salient::protocol::sim {

void Wire::push(std::string_view bytes, Micros now) {
  if (bytes.empty()) return;
  const double now_us = static_cast<double>(now.count());
  const double start = std::max(now_us, free_at_us_);
  if (rate_ > 0) free_at_us_ = start + static_cast<double>(bytes.size()) * 1e6 / rate_;
  chunks_.push_back({std::string(bytes), start});
}

std::string Wire::pop(Micros now) {
  std::string out;
  const double now_us = static_cast<double>(now.count());
  while (!chunks_.empty()) {
    Chunk& c = chunks_.front();
    std::size_t arrived = c.bytes.size();
    if (rate_ > 0) {
      const double n = std::floor((now_us - c.start_us) * rate_ / 1e6 + 1e-9);
      arrived = n <= 0 ? 0 : std::min(c.bytes.size(), static_cast<std::size_t>(n));
    }
    if (arrived <= c.taken) break;
    out.append(c.bytes, c.taken, arrived - c.taken);
    c.taken = arrived;
    if (c.taken < c.bytes.size()) break;
    chunks_.pop_front();
  }
  return out;
}

Micros Wire::next_arrival() const {
  if (chunks_.empty()) return Micros::max();
  const Chunk& c = chunks_.front();
  if (rate_ <= 0) return Micros(static_cast<long long>(c.start_us));
  return Micros(
      static_cast<long long>(std::ceil(c.start_us + static_cast<double>(c.taken + 1) * 1e6 / rate_)));
}

Micros Wire::last_arrival() const {
  if (chunks_.empty()) return Micros::max();
  const Chunk& c = chunks_.back();
  if (rate_ <= 0) return Micros(static_cast<long long>(c.start_us));
  return Micros(
      static_cast<long long>(std::ceil(c.start_us + static_cast<double>(c.bytes.size()) * 1e6 / rate_)));
}

}  // namespace salient::protocol::sim
