// Job: one model to slice, and what became of it. States: queued → running → done | failed |
// cancelled; phases of a running job: load, saliency, plan, toolpaths.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace salient::server {

enum class JobState { queued, running, done, failed, cancelled };

std::string_view to_string(JobState s);
std::optional<JobState> job_state_from(std::string_view s);
inline bool finished(JobState s) {
  return s == JobState::done || s == JobState::failed || s == JobState::cancelled;
}

struct Job {
  std::string id;
  JobState state = JobState::queued;
  std::string phase;    // empty until it runs
  double progress = 0;  // 0..1 within the whole job
  std::string filename, model_digest;
  std::string settings, settings_digest;  // settings as canonical JSON text
  std::optional<std::string> error;       // why it failed
  std::optional<std::string> result;      // JSON: layers, saving, estimate, artefact digests
  int attempts = 0;                       // times it started (a restart re-queues a running job)
  double created_at = 0;                  // seconds since the epoch
  std::optional<double> started_at, finished_at;
};

}  // namespace salient::server
