// JobStore: jobs in the database. Every change is one statement (or one transaction), so a
// crash leaves each job in a state it really had.
//
// Across nodes (one PostgreSQL, several salientd): a slicer node claims the oldest queued job
// (one UPDATE … FOR UPDATE SKIP LOCKED, so that claimers never wait for each other nor take the
// same job) and holds it by a lease it renews; a job whose lease expired is put back in the queue
// by whichever node notices (reap), the reason kept, until max_attempts claims have been lost and
// it fails. Only the holder of the claim (its node and attempt number) can finish a running job,
// so that a node that paused, lost its lease and came back cannot write over the job's new run.
//
// Clock: lease times (claim, renew, reap, started_at, lease_until) are the database's clock when
// `now` is empty, which is what the daemon passes: one clock for the farm, whatever the nodes'
// clocks say. Tests pass `now` to play with time. created_at is the submitting node's clock.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job.hpp"
#include "server/store/database.hpp"

namespace salient::server {

// Who holds a running job: the node that claimed it and the claim's attempt number (a job
// re-queued and claimed again, even by the same node, is a new claim).
struct JobClaim {
  std::string node;
  int attempts = 0;
};

// A running job of a node whose lease renew() extended.
struct JobLease {
  std::string id;
  int attempts = 0;
  bool cancel_requested = false;  // another node's API asked it to stop
};

class JobStore {
 public:
  explicit JobStore(Database& db) : db_(db) {}

  Job create(const std::string& filename, const std::string& model_digest, const std::string& settings,
             const std::string& settings_digest, double now);
  std::optional<Job> get(const std::string& id);
  // Newest first; `state` filters when given.
  std::vector<Job> list(std::optional<JobState> state, int limit, int offset);
  long long count(std::optional<JobState> state);
  // The oldest queued job, now running on `node` (attempts + 1) with a lease of lease_seconds;
  // none when the queue is empty. One statement: concurrent claimers each get another job.
  std::optional<Job> claim(const std::string& node, double lease_seconds, std::optional<double> now = {});
  // Extends the leases of all of `node`'s running jobs; returns those it still holds (a job not
  // in the list was taken from it) and whether a cancel was asked for each.
  std::vector<JobLease> renew(const std::string& node, double lease_seconds, std::optional<double> now = {});
  // Running jobs whose lease expired: back to the queue (node cleared, "node X stopped renewing
  // its lease" kept in requeues), or failed once they have been claimed max_attempts times, or
  // cancelled if a cancel was asked. Returns the jobs it changed. Safe with several reapers.
  std::vector<Job> reap(int max_attempts, std::optional<double> now = {});
  void set_progress(const std::string& id, JobPhase phase, double progress);
  // A running job → done | failed | cancelled (its phase back to none), by its holder only: false (and
  // nothing changed) when `holder` no longer holds it or it had already finished, so that a finish is
  // idempotent.
  bool finish(const std::string& id, const JobClaim& holder, JobState state,
              const std::optional<std::string>& error, const std::optional<std::string>& result,
              std::optional<double> now = {});
  // A queued job → cancelled; false if it was not queued.
  bool cancel_queued(const std::string& id, double now);
  // A running job on another node: asks its node (through renew) to stop it; false if not running.
  bool request_cancel(const std::string& id);
  // `node` restarts: its jobs that were running (and those of a daemon from before nodes, whose
  // node is empty) go back to the queue, or fail at max_attempts; returns the jobs changed.
  std::vector<Job> requeue_running(const std::string& node, int max_attempts, std::optional<double> now = {});
  // Its holder gives a running job back without an outcome (the database failed as the result was
  // stored): queued again with `reason`, or failed at max_attempts, as a reaped job.
  std::optional<Job> give_back(const Job& job, const std::string& reason, int max_attempts, double now);
  // A finished, successful job for the same model bytes and settings, to reuse.
  std::optional<Job> find_done(const std::string& model_digest, const std::string& settings_digest);
  bool remove(const std::string& id);

 private:
  std::optional<Job> requeue_one(const Job& job, const std::string& reason, double at, int max_attempts,
                                 bool only_if_expired);
  Database& db_;
};

}  // namespace salient::server
