// JobService: the job queue and its workers. A submitted model is stored (content-addressed)
// and checked, a job row is written (or a finished job for the same bytes and settings is
// reused), and a bounded pool of worker threads runs core::slice_model on queued jobs, oldest
// first, with progress in the database and cooperative cancellation. On stop, running jobs are
// interrupted and left "running", so that the next start re-queues them.
//
// Several nodes may share one PostgreSQL: workers claim jobs with a lease (JobStore::claim) and
// poll for jobs submitted elsewhere; a renewer thread extends this node's leases every third of
// a lease, stops a job it no longer holds (another node re-queued it: its result is not written)
// or that another node's API cancelled, and re-queues the jobs of nodes that stopped renewing.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/common/progress.hpp"
#include "core/saliency/saliency_cache.hpp"
#include "server/config/daemon_config.hpp"
#include "server/jobs/job.hpp"
#include "server/store/store.hpp"

namespace salient::server {

struct JobServiceOptions {
  int workers = 1;
  int queue_limit = 32;
  std::size_t max_json_depth = 32;
  int nice = 10;                     // workers' scheduling priority (Linux nice, per thread); 0 leaves it
  std::size_t saliency_cache = 4;    // models whose saliency the workers keep in memory (0: none)
  std::string node = "local";        // this node's id in the farm (DaemonConfig::node)
  double lease_seconds = 15;         // a claim not renewed within this is taken as lost
  int max_attempts = 3;              // claims a job may lose before it fails
  double time_limit_seconds = 1800;  // a job still slicing after this fails, naming the limit
};

class JobService {
 public:
  JobService(Store& store, JobServiceOptions options, std::function<void(const Job&)> on_change = {});
  ~JobService();

  void start();  // re-queues what a previous run left running, starts the workers
  // Interrupts running jobs (they stay re-queueable) and joins the workers. With `grace`, false
  // when a worker is still inside a computation after it: the caller may then exit without
  // joining (the job is "running" in the database and is re-queued at the next start).
  bool stop(std::optional<std::chrono::milliseconds> grace = std::nullopt);

  struct Submitted {
    Job job;
    bool reused = false;  // an earlier finished job with the same model bytes and settings
  };
  // Throws a DomainError: BadRequest (bad settings), Unsupported (not a mesh format), Unprocessable
  // (unreadable mesh), TooBusy (queue full).
  Submitted submit(const std::string& filename, const std::string& bytes, const std::string& settings_json);
  // Queued: cancelled at once; running: asked to stop. False when it had already finished.
  bool cancel(const std::string& id);
  // Saliency kept between jobs: a job on a model (placed the same way) that an earlier job has
  // computed the saliency of reuses it, whatever its other settings. Its counters are /metrics'.
  const core::SaliencyCache& saliency_cache() const { return saliency_cache_; }

 private:
  // A job this node runs: its worker's cancel token, and the claim (attempt) it holds.
  struct Running {
    std::shared_ptr<core::CancelToken> token;
    int attempts = 0;
    bool lost = false;  // another node took it: the outcome is not written
  };
  void work();
  void run(Job job, const std::shared_ptr<core::CancelToken>& token);
  void changed(const std::string& id);
  void renew_leases();
  void renewer();

  Store& store_;
  JobServiceOptions options_;
  std::function<void(const Job&)> on_change_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable renew_wake_;  // the renewer's own: a submit's notify_one is for a worker
  bool stopping_ = false;
  std::map<std::string, Running> running_;
  std::vector<std::thread> workers_;
  std::thread renewer_;
  std::size_t exited_ = 0;  // workers that have left their loop, under mutex_
  core::SaliencyCache saliency_cache_;
};

// The daemon's options: its [node]'s id, lease and attempts; no workers on a node that is not a
// slicer.
JobServiceOptions job_service_options(const DaemonConfig& config);

// File names from clients become "bunny.obj"-like names: letters, digits, '.', '-', '_' only.
std::string sanitize_filename(const std::string& name);

}  // namespace salient::server
