// TemperatureHistory: a printer's temperatures over the last half hour, in memory, for the page's
// chart (GET /api/v1/printers/{id}/temperatures). One sample a second at most: a printer reports
// several a second while printing, and a chart of 30 minutes needs no more than 1800 points.
#pragma once

#include <cstddef>
#include <deque>
#include <mutex>
#include <vector>

#include "server/printers/printer_status.hpp"

namespace salient::server {

struct TemperatureSample {
  double time = 0;  // seconds since the epoch (as events' "time")
  Temperature hotend, bed;
};

class TemperatureHistory {
 public:
  explicit TemperatureHistory(double window_seconds = 1800, double spacing_seconds = 1)
      : window_(window_seconds), spacing_(spacing_seconds) {}

  // Whether a sample at `now` would be kept (cheap: lets the caller skip reading the status).
  bool due(double now) const;
  // Keeps the sample unless the last one is under `spacing` old; forgets what is older than the
  // window. A sample without any reading (a disconnected printer) is kept too: the chart's gap.
  void add(const TemperatureSample& sample);
  // The samples of the window ending at `now`, oldest first.
  std::vector<TemperatureSample> samples(double now) const;
  double window() const { return window_; }

 private:
  double window_, spacing_;
  mutable std::mutex mutex_;
  std::deque<TemperatureSample> samples_;
};

}  // namespace salient::server
