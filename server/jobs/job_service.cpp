#include "server/jobs/job_service.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/common/input_error.hpp"
#include "core/export/plan_json.hpp"
#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/mesh_reader.hpp"
#include "core/mesh/placement.hpp"
#include "core/pipeline/placed_model.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/pipeline/slice_result_json.hpp"
#include "core/pipeline/slice_warning.hpp"
#include "core/pipeline/work_bounds.hpp"
#include "core/printer/printer_profile.hpp"
#include "server/common/domain_error.hpp"
#include "server/common/json_text.hpp"
#include "server/jobs/job_progress.hpp"
#include "server/jobs/job_settings.hpp"
#include "server/store/job_store.hpp"
#include "server/store/sha256.hpp"

namespace salient::server {
namespace {

namespace fs = std::filesystem;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

core::PrinterProfile printer_for(const std::string& id) {
  if (auto p = core::builtin_printer(id)) return *p;
  std::string known;
  for (const std::string& k : core::builtin_printer_ids()) known += (known.empty() ? "" : ", ") + k;
  throw BadRequest("bad_settings", "settings: unknown printer '" + id + "' (built in: " + known + ")");
}

// The work the settings ask of this model, bounded as slice_model bounds it when it runs (its
// check after placing), refused now (422) rather than as a failed job or a daemon out of memory.
// "auto" places the model three ways when it runs: each is checked then.
void check_work(const std::string& name, const core::Mesh& mesh, const core::SliceSettings& slice,
                const core::PrinterProfile& printer) {
  const core::MeshOptions& options = slice.plan.mesh;
  if (options.up == "auto") return;
  core::Mesh placed;
  placed.positions = mesh.positions;
  placed.triangles = mesh.triangles;
  try {
    const core::Placement placement = core::place_by_options(placed, options);
    core::check_work_bounds(
        placement.bounds, options, slice.min_layer_from_printer ? printer.min_layer : slice.plan.min_layer,
        slice.plan.grid, core::BuildVolume{printer.bed_width, printer.bed_depth, printer.max_height});
  } catch (const core::InputError& e) {
    // A setting at fault is named as the settings' other refusals name it; else the model is.
    throw Unprocessable("too_much_work",
                        e.setting() ? "settings: " + e.spelled(quoted_setting)
                                    : name + ": " + core::spell_settings(e.message(), quoted_setting));
  }
}

// A model that would leave nothing printed is 422 at once, not a job that fails (or a one-layer
// job that "succeeds") later: placed as the settings place it (with "up": "auto", by its largest
// side, which the chosen orientation can at most make its height).
void check_printable(core::Mesh mesh, const core::MeshOptions& options, const core::PrinterProfile& printer,
                     const std::string& name) {
  core::PlacementOptions placement;
  const bool automatic = options.up == "auto";
  if (!automatic) {
    if (const auto up = core::parse_up_axis(options.up))
      placement.up = *up;
    else
      placement.up_direction = core::parse_up_direction(options.up);
  }
  placement.target_height = options.height;
  placement.scale = options.scale;
  core::BoundingBox placed;
  try {
    placed = core::place_mesh(mesh, placement).bounds;
  } catch (const core::InputError& e) {  // e.g. a flat model given a height
    throw Unprocessable("unplaceable_model", e.spelled(quoted_setting));
  }
  if (automatic) placed.max.z = std::max({placed.size().x, placed.size().y, placed.size().z});
  try {
    core::check_printable_height(placed, printer.first_layer_height, name);
  } catch (const core::InputError& e) {
    throw Unprocessable("model_too_small", e.spelled(quoted_setting));
  }
}

}  // namespace

std::string sanitize_filename(const std::string& name) {
  std::string base =
      name.substr(name.find_last_of("/\\") == std::string::npos ? 0 : name.find_last_of("/\\") + 1);
  std::string out;
  for (char c : base) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '-' || c == '_';
    out += ok ? c : '_';
  }
  if (out.size() > 100) out = out.substr(out.size() - 100);    // the end keeps the extension
  while (!out.empty() && out.front() == '.') out.erase(0, 1);  // then: no hidden files, no ".."
  return out.empty() ? "model" : out;
}

namespace {

// What a job that ran out of time says: the limit, in a person's units, and where it is set.
std::string time_limit_text(double seconds) {
  const long minutes = std::lround(seconds / 60);
  const std::string limit =
      minutes >= 1 ? std::to_string(minutes) + " min" : std::to_string(std::lround(seconds)) + " s";
  return "the slice took longer than the " + limit +
         " a job may run ([jobs] time_limit_minutes in salientd's config): try a coarser 'grid', "
         "saliency 'lee05' or 'uniform', or a smaller model";
}

}  // namespace

JobServiceOptions job_service_options(const DaemonConfig& config) {
  JobServiceOptions o;
  o.workers = config.node.roles.slicer ? config.workers : 0;
  o.queue_limit = config.queue_limit;
  o.max_json_depth = static_cast<std::size_t>(config.max_json_depth);
  o.node = config.node.id;
  o.lease_seconds = config.node.lease_seconds;
  o.max_attempts = config.node.max_attempts;
  o.time_limit_seconds = config.job_time_limit_minutes * 60;
  return o;
}

JobService::JobService(Store& store, JobServiceOptions options, std::function<void(const Job&)> on_change)
    : store_(store),
      options_(options),
      on_change_(std::move(on_change)),
      saliency_cache_(options.saliency_cache) {}

JobService::~JobService() {
  stop();
}

void JobService::start() {
  // Only this node's own (and those of a daemon from before nodes): another node's running jobs
  // are its own business until their lease expires.
  for (const Job& j : JobStore(store_.db()).requeue_running(options_.node, options_.max_attempts))
    if (on_change_) on_change_(j);
  std::lock_guard lock(mutex_);
  stopping_ = false;
  for (int i = 0; i < options_.workers; ++i) workers_.emplace_back([this] { work(); });
  renewer_ = std::thread([this] { renewer(); });
}

bool JobService::stop(std::optional<std::chrono::milliseconds> grace) {
  {
    std::unique_lock lock(mutex_);
    stopping_ = true;
    for (auto& [id, r] : running_) r.token->cancel();
    wake_.notify_all();
    renew_wake_.notify_all();
    // A job notices its cancel at the computation's next check, which one long solve may delay.
    if (grace && !wake_.wait_for(lock, *grace, [&] { return exited_ == workers_.size(); })) return false;
  }
  for (auto& t : workers_) t.join();
  workers_.clear();
  if (renewer_.joinable()) renewer_.join();
  exited_ = 0;
  return true;
}

void JobService::changed(const std::string& id) {
  if (!on_change_) return;
  if (auto j = JobStore(store_.db()).get(id)) on_change_(*j);
}

JobService::Submitted JobService::submit(const std::string& filename, const std::string& bytes,
                                         const std::string& settings_json) {
  const JobSettings settings = parse_job_settings(settings_json, options_.max_json_depth);
  const core::PrinterProfile printer = printer_for(settings.printer);
  const std::string name = sanitize_filename(filename);
  if (!core::detect_format(bytes, name))
    throw Unsupported("unsupported_format", name + ": not an STL, OBJ, PLY or OFF model");
  core::LoadedMesh loaded;
  try {
    loaded = core::load_mesh(
        bytes, name);  // read and repaired: no usable triangle is 422 now, not a failed job later
  } catch (const core::InputError& e) {
    throw Unprocessable("unreadable_mesh", e.what());
  }
  check_printable(loaded.mesh, settings.slice.plan.mesh, printer, name);
  check_work(name, loaded.mesh, settings.slice, printer);
  if (settings.slice.plan.saliency == core::SaliencyMethod::painted && !loaded.mesh.has_quality() &&
      !loaded.mesh.has_colors())
    throw Unprocessable("no_painted_saliency",
                        name +
                            ": 'saliency' painted needs vertex quality or vertex colours (a PLY's quality or "
                            "red property, an OBJ's v x y z r g b), and the model has neither");
  std::lock_guard files_lock(store_.files_mutex());  // the file and its row land together
  const std::string digest = store_.files().put(bytes);
  const std::string settings_digest = sha256_hex(settings.canonical);
  JobStore jobs(store_.db());
  if (auto done = jobs.find_done(digest, settings_digest)) return {*done, true};
  if (jobs.count(JobState::queued) >= options_.queue_limit)
    throw TooBusy("queue_full",
                  "the job queue is full (" + std::to_string(options_.queue_limit) + " waiting)", 30);
  Job job;
  {
    // "queued" is told inside the transaction that writes the row: no slicer, here or on another
    // node, can claim the job (and tell "running") before it. Not under mutex_: a worker holds it
    // while it waits for the database.
    Database::Transaction t(store_.db());
    job = jobs.create(name, digest, settings.canonical, settings_digest, now_seconds());
    if (on_change_) on_change_(job);
    t.commit();
  }
  wake_.notify_one();
  return {job, false};
}

bool JobService::cancel(const std::string& id) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = running_.find(id); it != running_.end()) {
      it->second.token->cancel();
      return true;
    }
  }
  JobStore jobs(store_.db());
  if (jobs.cancel_queued(id, now_seconds())) {
    changed(id);
    return true;
  }
  // Running on another node: it sees the request when it next renews its lease.
  return jobs.request_cancel(id);
}

void JobService::renewer() {
  const auto period = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options_.lease_seconds / 3));
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      if (renew_wake_.wait_for(lock, period, [&] { return stopping_; })) return;
    }
    try {
      renew_leases();
      // Any node reaps: each expired claim is changed by one reaper only (JobStore::reap).
      for (const Job& j : JobStore(store_.db()).reap(options_.max_attempts))
        if (on_change_) on_change_(j);
    } catch (const std::exception&) {
      // The database is away (or a row it could not read): the next period tries again; a
      // lease this node could not renew may expire meanwhile, and its job is then re-queued.
    }
  }
}

void JobService::renew_leases() {
  // Under mutex_, as claims are: a job claimed between the renewal and the check would look lost.
  std::lock_guard lock(mutex_);
  if (running_.empty()) return;
  const std::vector<JobLease> held = JobStore(store_.db()).renew(options_.node, options_.lease_seconds);
  for (auto& [id, r] : running_) {
    const auto it = std::find_if(held.begin(), held.end(),
                                 [&](const JobLease& l) { return l.id == id && l.attempts == r.attempts; });
    if (it == held.end()) {
      r.lost = true;  // re-queued by another node (we paused past our lease): stop, write nothing
      r.token->cancel();
    } else if (it->cancel_requested) {
      r.token->cancel();
    }
  }
}

void JobService::work() {
  // Slicing is batch work: below the HTTP threads and the printers' streaming threads, which must
  // answer in milliseconds. The thread pool the saliency solver starts from here inherits it.
  if (options_.nice > 0) setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), options_.nice);
  for (;;) {
    std::optional<Job> job;
    auto token = std::make_shared<core::CancelToken>();
    try {
      std::unique_lock lock(mutex_);
      if (stopping_) {
        ++exited_;
        wake_.notify_all();  // stop() may be waiting for the last worker
        return;
      }
      job = JobStore(store_.db()).claim(options_.node, options_.lease_seconds);
      if (!job) {
        // Polled: jobs are submitted on other nodes too.
        wake_.wait_for(lock, std::chrono::milliseconds(500));
        continue;
      }
      // Registered in the same step that makes it running: a cancel can never fall between.
      running_[job->id] = {token, job->attempts};
    } catch (const StoreError&) {  // a full disk: no job can start now; space may come back
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::seconds(1));
      continue;
    }
    run(*job, token);
  }
}

void JobService::run(Job job, const std::shared_ptr<core::CancelToken>& token) {
  token->expire_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(options_.time_limit_seconds)));
  changed(job.id);
  const fs::path work = store_.data_dir() / "work" / job.id;
  std::mutex progress_mutex;
  JobProgress progress;
  core::RunContext run{token.get(), [&](std::string_view reported, double fraction) {
                         std::lock_guard lock(progress_mutex);  // reported from the solvers' threads too
                         const auto update = progress.report(reported, fraction);
                         if (!update) return;
                         try {
                           JobStore(store_.db()).set_progress(job.id, update->phase, update->overall);
                         } catch (const StoreError&) {
                           return;  // a full disk: progress is not worth failing the job for
                         }
                         changed(job.id);
                       }};
  std::optional<std::string> error, result;
  JobState end = JobState::done;
  std::optional<std::string> give_back;  // the database failed as the result was stored: why
  try {
    JobSettings settings = parse_job_settings(job.settings, options_.max_json_depth);
    const core::PrinterProfile printer = printer_for(settings.printer);
    fs::create_directories(work);
    const fs::path model = work / job.filename;  // sanitised when the job was made
    fs::remove(model);
    fs::create_symlink(fs::absolute(store_.files().path_of(job.model_digest)), model);
    settings.slice.plan.mesh.model = model.string();
    settings.slice.artefacts = true;
    settings.slice.plan.saliency_cache = &saliency_cache_;
    const core::SliceResult r = core::slice_model(settings.slice, printer, run);
    run.check();  // a cancel that came as the slicing ended: nothing is stored
    const std::string gcode = store_.files().put(r.gcode);
    const std::string plan_digest = store_.files().put(core::plan_json(r.plan));  // as `salient plan -o`
    // The figures as `salient slice --json` prints them (one writer), then the files made.
    nlohmann::json figures = nlohmann::json::parse(core::slice_result_json(r, printer.id, quoted_setting));
    figures["gcode"] = gcode;
    figures["plan"] = plan_digest;
    figures["plot"] = store_.files().put(r.plot_svg);
    figures["model"] = store_.files().put(r.model_3mf);
    figures["saliency"] = store_.files().put(r.saliency_ply);
    result = json_text(figures);
  } catch (const core::Cancelled&) {
    end = JobState::cancelled;
    // Out of time, unless a person's cancel came first: that one is what they asked for.
    if (token->expired() && !token->cancel_called())
      end = JobState::failed, error = time_limit_text(options_.time_limit_seconds);
  } catch (const StoreError& e) {
    // The database (PostgreSQL restarting, a full disk) is no fault of the job: it is queued
    // again, not failed for good.
    give_back = std::string("the database failed as its result was stored: ") + e.what();
  } catch (const core::InputError& e) {
    end = JobState::failed, error = e.what();
  } catch (const DomainError& e) {
    end = JobState::failed, error = e.what();
  } catch (const std::exception& e) {
    end = JobState::failed, error = std::string("internal error: ") + e.what();
  }
  std::error_code ec;
  fs::remove_all(work, ec);
  bool shutting_down, lost;
  {
    std::lock_guard lock(mutex_);
    lost = running_[job.id].lost;
    running_.erase(job.id);
    shutting_down = stopping_;
    // cancel() said yes once the token was set, however late: the job ends cancelled, not done.
    // A deadline passed after the slice ended is no cancel: its result stands.
    if (token->cancelled() && !token->expired() && end == JobState::done)
      end = JobState::cancelled, result.reset();
  }
  if (end == JobState::cancelled && shutting_down) return;  // interrupted by a stop: re-queued next start
  if (lost) return;  // another node runs it now, or has re-queued it: its outcome is not ours
  if (give_back && end != JobState::cancelled) {
    for (int attempt = 0;; ++attempt) {
      try {
        JobStore(store_.db()).give_back(job, *give_back, options_.max_attempts, now_seconds());
        break;
      } catch (const StoreError&) {  // still away: tried for a minute, then left to the lease
        std::unique_lock lock(mutex_);
        if (stopping_ || attempt >= 60) return;
        wake_.wait_for(lock, std::chrono::seconds(1));
      }
    }
    changed(job.id);
    wake_.notify_all();  // a worker may take it again at once
    return;
  }
  // A full disk may free up: the outcome is retried for a while; if it never lands, the job is
  // still "running" in the database and is re-queued at the next start.
  for (int attempt = 0;; ++attempt) {
    try {
      // Rejected (nothing written) if this node no longer holds the claim.
      if (!JobStore(store_.db()).finish(job.id, {options_.node, job.attempts}, end, error, result)) return;
      break;
    } catch (const StoreError&) {
      std::unique_lock lock(mutex_);
      if (stopping_ || attempt >= 60) return;
      wake_.wait_for(lock, std::chrono::seconds(1));
    }
  }
  changed(job.id);
}

}  // namespace salient::server
