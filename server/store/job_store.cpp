#include "server/store/job_store.hpp"

#include <random>

namespace salient::server {
namespace {

constexpr const char* columns =
    "id, state, phase, progress, filename, model_digest, settings, settings_digest, error, result, attempts, "
    "created_at, "
    "started_at, finished_at";

Job read_job(const Database::Statement& q) {
  Job j;
  j.id = q.text(0);
  j.state = job_state_from(q.text(1)).value_or(JobState::failed);
  j.phase = job_phase_from(q.text(2)).value_or(JobPhase::none);
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
  return j;
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

std::optional<Job> JobStore::start_next(double now) {
  Database::Transaction t(db_);
  auto q = db_.prepare(std::string("SELECT ") + columns +
                       " FROM jobs WHERE state = 'queued' ORDER BY created_at, rowid LIMIT 1");
  if (!q.step()) return std::nullopt;
  Job j = read_job(q);
  q.run();
  db_.prepare(
         "UPDATE jobs SET state = 'running', attempts = attempts + 1, started_at = ?, phase = 'load', "
         "progress = 0 WHERE id = ?")
      .bind(1, now)
      .bind(2, std::string_view(j.id))
      .run();
  t.commit();
  j.state = JobState::running;
  j.attempts += 1;
  j.started_at = now;
  return j;
}

void JobStore::set_progress(const std::string& id, JobPhase phase, double progress) {
  db_.prepare("UPDATE jobs SET phase = ?, progress = ? WHERE id = ? AND state = 'running'")
      .bind(1, to_string(phase))
      .bind(2, progress)
      .bind(3, std::string_view(id))
      .run();
}

bool JobStore::finish(const std::string& id, JobState state, const std::optional<std::string>& error,
                      const std::optional<std::string>& result, double now) {
  db_.prepare(
         "UPDATE jobs SET state = ?, error = ?, result = ?, finished_at = ?, progress = CASE WHEN ? = 'done' "
         "THEN 1 "
         "ELSE progress END WHERE id = ? AND state IN ('queued', 'running')")
      .bind(1, to_string(state))
      .bind(2, error)
      .bind(3, result)
      .bind(4, now)
      .bind(5, to_string(state))
      .bind(6, std::string_view(id))
      .run();
  return db_.changes() > 0;
}

int JobStore::requeue_running() {
  db_.exec("UPDATE jobs SET state = 'queued', phase = '', progress = 0 WHERE state = 'running'");
  return db_.changes();
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
