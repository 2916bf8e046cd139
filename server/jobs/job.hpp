// Job: one model to slice, and what became of it. Its states and phases (all of them listed
// there) are in server/jobs/job_state.hpp.
#pragma once

#include <optional>
#include <string>

#include "server/jobs/job_state.hpp"

namespace salient::server {

struct Job {
  std::string id;
  JobState state = JobState::queued;
  JobPhase phase = JobPhase::none;  // none until it runs
  double progress = 0;              // 0..1 within the whole job
  std::string filename, model_digest;
  std::string settings, settings_digest;  // settings as canonical JSON text
  std::optional<std::string> error;       // why it failed
  std::optional<std::string> result;      // JSON: layers, saving, estimate, artefact digests
  int attempts = 0;                       // times it started (a restart re-queues a running job)
  double created_at = 0;                  // seconds since the epoch
  std::optional<double> started_at, finished_at;
  // Across nodes (server/store/job_store.hpp): the node holding a running job's claim, until when
  // (the database's clock), whether another node asked it to stop, and why the job went back to
  // the queue each time (JSON: [{"node", "at", "reason"}, …]).
  std::optional<std::string> node;
  std::optional<double> lease_until;
  bool cancel_requested = false;
  std::string requeues = "[]";
};

}  // namespace salient::server
