// JobStore: jobs in the database. Every change is one statement (or one transaction), so a
// crash leaves each job in a state it really had.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job.hpp"
#include "server/store/database.hpp"

namespace salient::server {

class JobStore {
 public:
  explicit JobStore(Database& db) : db_(db) {}

  Job create(const std::string& filename, const std::string& model_digest, const std::string& settings,
             const std::string& settings_digest, double now);
  std::optional<Job> get(const std::string& id);
  // Newest first; `state` filters when given.
  std::vector<Job> list(std::optional<JobState> state, int limit, int offset);
  long long count(std::optional<JobState> state);
  // The oldest queued job, now running (attempts + 1); none when the queue is empty.
  std::optional<Job> start_next(double now);
  void set_progress(const std::string& id, JobPhase phase, double progress);
  // running/queued → done | failed | cancelled; false if it had already finished.
  bool finish(const std::string& id, JobState state, const std::optional<std::string>& error,
              const std::optional<std::string>& result, double now);
  // A restart: jobs that were running go back to the queue; returns how many.
  int requeue_running();
  // A finished, successful job for the same model bytes and settings, to reuse.
  std::optional<Job> find_done(const std::string& model_digest, const std::string& settings_digest);
  bool remove(const std::string& id);

 private:
  Database& db_;
};

}  // namespace salient::server
