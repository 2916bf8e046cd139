// JobProgress: how the core's progress reports (core::RunContext: "load", "saliency", "lee05",
// "profile", "plan" or a planner's own name, "orient", "segment", "toolpaths", "gcode") become a
// job's phase and its progress over the whole job, and which of them are worth writing down.
#pragma once

#include <chrono>
#include <optional>
#include <string_view>

#include "server/jobs/job_state.hpp"

namespace salient::server {

class JobProgress {
 public:
  struct Update {
    JobPhase phase;
    double overall;  // 0..1 of the whole job
  };
  // The update to store for a report of `fraction` (0..1) of core phase `reported`, or none when
  // it is hidden (a planner's own progress inside SegOpt) or too close to the last one stored (in
  // the same phase, less than 2 % on and 100 ms later). Not thread-safe: the caller serialises.
  std::optional<Update> report(std::string_view reported, double fraction,
                               std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

 private:
  bool oriented_ = false;    // with "up": "auto", "orient" takes the first 30 % and the rest follows
  bool segmenting_ = false;  // with "segment", its own progress stands for the planners' inside it
  std::optional<JobPhase> last_phase_;
  double last_overall_ = -1;
  std::chrono::steady_clock::time_point last_write_{};
};

}  // namespace salient::server
