#include "server/printers/temperature_history.hpp"

namespace salient::server {

bool TemperatureHistory::due(double now) const {
  std::lock_guard lock(mutex_);
  return samples_.empty() || now - samples_.back().time >= spacing_ || now < samples_.back().time;
}

void TemperatureHistory::add(const TemperatureSample& sample) {
  std::lock_guard lock(mutex_);
  // A clock set back starts the history again rather than leaving it out of order.
  if (!samples_.empty() && sample.time < samples_.back().time) samples_.clear();
  if (!samples_.empty() && sample.time - samples_.back().time < spacing_) return;
  samples_.push_back(sample);
  while (!samples_.empty() && samples_.front().time < sample.time - window_) samples_.pop_front();
}

std::vector<TemperatureSample> TemperatureHistory::samples(double now) const {
  std::lock_guard lock(mutex_);
  std::vector<TemperatureSample> out;
  for (const TemperatureSample& s : samples_)
    if (s.time >= now - window_) out.push_back(s);
  return out;
}

}  // namespace salient::server
