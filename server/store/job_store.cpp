#include "server/store/job_store.hpp"

#include <nlohmann/json.hpp>
#include <random>

namespace salient::server {
namespace {

constexpr const char* columns =
    "id, state, phase, progress, filename, model_digest, settings, settings_digest, error, result, attempts, "
    "created_at, "
    "started_at, finished_at, node, lease_until, cancel_requested, requeues";
constexpr int column_count = 18;

Job read_job(const Database::Statement& q) {
  Job j;
  j.id = q.text(0);
  j.state = job_state_from(q.text(1)).value_or(JobState::failed);
  // A phase is a running job's: rows finished before finish() cleared it still say "toolpaths".
  j.phase =
      j.state == JobState::running ? job_phase_from(q.text(2)).value_or(JobPhase::none) : JobPhase::none;
  j.progress = q.real(3);
  j.filename = q.text(4);
  j.model_digest = q.text(5);
  j.settings = q.text(6);
  j.settings_digest = q.text(7);
  if (!q.null(8)) j.error = q.text(8);
  if (!q.null(9)) j.result = q.text(9);
  j.attempts = static_cast<int>(q.integer(10));
  j.created_at = q.real(11);
  if (!q.null(12)) j.started_at = q.real(12);
  if (!q.null(13)) j.finished_at = q.real(13);
  if (!q.null(14)) j.node = q.text(14);
  if (!q.null(15)) j.lease_until = q.real(15);
  j.cancel_requested = q.integer(16) != 0;
  j.requeues = q.text(17);
  return j;
}

void bind_time(Database::Statement& q, int index, std::optional<double> now) {
  if (now)
    q.bind(index, *now);
  else
    q.bind_null(index);
}

// requeues with one more entry, and the error of a job that gave up: every reason, in order.
std::string appended(const std::string& requeues, const std::string& node, double at,
                     const std::string& reason) {
  nlohmann::json list = nlohmann::json::parse(requeues, nullptr, false);
  if (!list.is_array()) list = nlohmann::json::array();
  list.push_back({{"node", node}, {"at", at}, {"reason", reason}});
  return list.dump();
}

std::string gave_up(const std::string& requeues, int attempts) {
  std::string reasons;
  for (const auto& r : nlohmann::json::parse(requeues))
    if (r.is_object() && r.contains("reason") && r["reason"].is_string())
      reasons += (reasons.empty() ? "" : "; ") + r["reason"].get<std::string>();
  return "gave up after " + std::to_string(attempts) + " attempts: " + reasons;
}

std::string new_id() {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  static constexpr char digits[] = "0123456789abcdef";
  std::string id = "j";
  std::uint64_t bits = rng();
  for (int i = 0; i < 15; ++i, bits >>= 4) id += digits[bits & 15];
  return id;
}

}  // namespace

Job JobStore::create(const std::string& filename, const std::string& model_digest,
                     const std::string& settings, const std::string& settings_digest, double now) {
  Job j;
  j.id = new_id();
  j.filename = filename;
  j.model_digest = model_digest;
  j.settings = settings;
  j.settings_digest = settings_digest;
  j.created_at = now;
  db_.prepare(
         "INSERT INTO jobs (id, state, filename, model_digest, settings, settings_digest, created_at) "
         "VALUES (?, 'queued', ?, ?, ?, ?, ?)")
      .bind(1, std::string_view(j.id))
      .bind(2, std::string_view(filename))
      .bind(3, std::string_view(model_digest))
      .bind(4, std::string_view(settings))
      .bind(5, std::string_view(settings_digest))
      .bind(6, now)
      .run();
  return j;
}

std::optional<Job> JobStore::get(const std::string& id) {
  auto q = db_.prepare(std::string("SELECT ") + columns + " FROM jobs WHERE id = ?");
  q.bind(1, std::string_view(id));
  if (!q.step()) return std::nullopt;
  Job j = read_job(q);
  q.run();
  return j;
}

std::vector<Job> JobStore::list(std::optional<JobState> state, int limit, int offset) {
  auto q = db_.prepare(std::string("SELECT ") + columns +
                       " FROM jobs WHERE (CAST(?1 AS TEXT) IS NULL OR state = ?1) " +
                       "ORDER BY created_at DESC, rowid DESC LIMIT ?2 OFFSET ?3");
  if (state)
    q.bind(1, to_string(*state));
  else
    q.bind_null(1);
  q.bind(2, static_cast<std::int64_t>(limit)).bind(3, static_cast<std::int64_t>(offset));
  std::vector<Job> out;
  while (q.step()) out.push_back(read_job(q));
  return out;
}

long long JobStore::count(std::optional<JobState> state) {
  auto q = db_.prepare("SELECT count(*) FROM jobs WHERE (CAST(?1 AS TEXT) IS NULL OR state = ?1)");
  if (state)
    q.bind(1, to_string(*state));
  else
    q.bind_null(1);
  q.step();
  const long long n = q.integer(0);
  q.run();
  return n;
}

std::optional<Job> JobStore::claim(const std::string& node, double lease_seconds, std::optional<double> now) {
  // One statement, no lock: on PostgreSQL the subquery locks the row it picks and skips those
  // other claimers hold, and the outer state check drops a row that stopped being queued.
  auto q = db_.prepare(dialect_sql(
      db_,
      std::string("UPDATE jobs SET state = 'running', attempts = attempts + 1, node = ?1, ") +
          "started_at = COALESCE(CAST(?3 AS {REAL}), {NOW}), "
          "lease_until = COALESCE(CAST(?3 AS {REAL}), {NOW}) + ?2, cancel_requested = 0, phase = 'load', "
          "progress = 0 WHERE state = 'queued' AND id = (SELECT id FROM jobs WHERE state = 'queued' "
          "ORDER BY created_at, rowid LIMIT 1{SKIP_LOCKED}) RETURNING " +
          columns));
  q.bind(1, std::string_view(node)).bind(2, lease_seconds);
  bind_time(q, 3, now);
  if (!q.step()) return std::nullopt;
  Job j = read_job(q);
  q.run();
  return j;
}

std::vector<JobLease> JobStore::renew(const std::string& node, double lease_seconds,
                                      std::optional<double> now) {
  auto q = db_.prepare(dialect_sql(
      db_,
      "UPDATE jobs SET lease_until = COALESCE(CAST(?3 AS {REAL}), {NOW}) + ?2 WHERE node = ?1 AND "
      "state = 'running' RETURNING id, attempts, cancel_requested"));
  q.bind(1, std::string_view(node)).bind(2, lease_seconds);
  bind_time(q, 3, now);
  std::vector<JobLease> out;
  while (q.step()) out.push_back({q.text(0), static_cast<int>(q.integer(1)), q.integer(2) != 0});
  return out;
}

std::vector<Job> JobStore::reap(int max_attempts, std::optional<double> now) {
  auto q =
      db_.prepare(dialect_sql(db_, std::string("SELECT ") + columns +
                                       ", COALESCE(CAST(?1 AS {REAL}), {NOW}) FROM jobs WHERE state = "
                                       "'running' AND lease_until < COALESCE(CAST(?1 AS {REAL}), {NOW})"));
  bind_time(q, 1, now);
  std::vector<std::pair<Job, double>> expired;
  while (q.step()) expired.emplace_back(read_job(q), q.real(column_count));
  std::vector<Job> out;
  for (const auto& [job, at] : expired) {
    const std::string reason = "node " + job.node.value_or("") + " stopped renewing its lease";
    if (auto changed = requeue_one(job, reason, at, max_attempts, true)) out.push_back(*changed);
  }
  return out;
}

std::vector<Job> JobStore::requeue_running(const std::string& node, int max_attempts,
                                           std::optional<double> now) {
  auto q = db_.prepare(dialect_sql(db_, std::string("SELECT ") + columns +
                                            ", COALESCE(CAST(?2 AS {REAL}), {NOW}) FROM jobs WHERE state = "
                                            "'running' AND (node = ?1 OR node IS NULL)"));
  q.bind(1, std::string_view(node));
  bind_time(q, 2, now);
  std::vector<std::pair<Job, double>> mine;
  while (q.step()) mine.emplace_back(read_job(q), q.real(column_count));
  std::vector<Job> out;
  for (const auto& [job, at] : mine) {
    const std::string reason = "node " + node + " restarted while running it";
    if (auto changed = requeue_one(job, reason, at, max_attempts, false)) out.push_back(*changed);
  }
  return out;
}

std::optional<Job> JobStore::give_back(const Job& job, const std::string& reason, int max_attempts,
                                       double now) {
  return requeue_one(job, reason, now, max_attempts, false);
}

// One job's claim ends without an outcome: queued again, or failed at the cap, or cancelled if a
// cancel was asked. Compare-and-set on the claim (state, node, attempts, and the lease still
// expired): of several nodes reaping the same job at once, one changes it and the others nothing.
std::optional<Job> JobStore::requeue_one(const Job& job, const std::string& reason, double at,
                                         int max_attempts, bool only_if_expired) {
  const std::string requeues = appended(job.requeues, job.node.value_or(""), at, reason);
  JobState state = JobState::queued;
  std::optional<std::string> error;
  if (job.cancel_requested) {
    state = JobState::cancelled;
  } else if (max_attempts > 0 && job.attempts >= max_attempts) {
    state = JobState::failed;
    error = gave_up(requeues, job.attempts);
  }
  auto q = db_.prepare(dialect_sql(
      db_,
      std::string("UPDATE jobs SET state = ?1, requeues = ?2, error = ?3, finished_at = ?4, node = NULL, ") +
          "lease_until = NULL, cancel_requested = 0, phase = '', progress = 0 WHERE id = ?5 AND state = "
          "'running' AND attempts = ?6 AND COALESCE(node, '') = ?7 AND (?8 = 0 OR lease_until < ?9) "
          "RETURNING " +
          columns));
  q.bind(1, to_string(state)).bind(2, std::string_view(requeues)).bind(3, error);
  if (state == JobState::queued)
    q.bind_null(4);
  else
    q.bind(4, at);
  q.bind(5, std::string_view(job.id))
      .bind(6, static_cast<std::int64_t>(job.attempts))
      .bind(7, std::string_view(job.node.value_or("")))
      .bind(8, static_cast<std::int64_t>(only_if_expired ? 1 : 0))
      .bind(9, at);
  if (!q.step()) return std::nullopt;
  Job j = read_job(q);
  q.run();
  return j;
}

void JobStore::set_progress(const std::string& id, JobPhase phase, double progress) {
  db_.prepare("UPDATE jobs SET phase = ?, progress = ? WHERE id = ? AND state = 'running'")
      .bind(1, to_string(phase))
      .bind(2, progress)
      .bind(3, std::string_view(id))
      .run();
}

bool JobStore::finish(const std::string& id, const JobClaim& holder, JobState state,
                      const std::optional<std::string>& error, const std::optional<std::string>& result,
                      std::optional<double> now) {
  auto q = db_.prepare(dialect_sql(
      db_,
      "UPDATE jobs SET state = ?1, error = ?2, result = ?3, finished_at = COALESCE(CAST(?4 AS {REAL}), "
      "{NOW}), "
      "lease_until = NULL, phase = '', progress = CASE WHEN ?1 = 'done' THEN 1 ELSE progress END WHERE id = "
      "?5 AND "
      "state = 'running' AND node = ?6 AND attempts = ?7"));
  q.bind(1, to_string(state)).bind(2, error).bind(3, result);
  bind_time(q, 4, now);
  q.bind(5, std::string_view(id))
      .bind(6, std::string_view(holder.node))
      .bind(7, static_cast<std::int64_t>(holder.attempts))
      .run();
  return db_.changes() > 0;
}

bool JobStore::cancel_queued(const std::string& id, double now) {
  db_.prepare("UPDATE jobs SET state = 'cancelled', finished_at = ? WHERE id = ? AND state = 'queued'")
      .bind(1, now)
      .bind(2, std::string_view(id))
      .run();
  return db_.changes() > 0;
}

bool JobStore::request_cancel(const std::string& id) {
  db_.prepare("UPDATE jobs SET cancel_requested = 1 WHERE id = ? AND state = 'running'")
      .bind(1, std::string_view(id))
      .run();
  return db_.changes() > 0;
}

std::optional<Job> JobStore::find_done(const std::string& model_digest, const std::string& settings_digest) {
  auto q = db_.prepare(std::string("SELECT ") + columns +
                       " FROM jobs WHERE model_digest = ? AND settings_digest = ? AND state = 'done' "
                       "ORDER BY finished_at DESC LIMIT 1");
  q.bind(1, std::string_view(model_digest)).bind(2, std::string_view(settings_digest));
  if (!q.step()) return std::nullopt;
  Job j = read_job(q);
  q.run();
  return j;
}

bool JobStore::remove(const std::string& id) {
  db_.prepare("DELETE FROM jobs WHERE id = ?").bind(1, std::string_view(id)).run();
  return db_.changes() > 0;
}

}  // namespace salient::server
