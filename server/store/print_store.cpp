#include "server/store/print_store.hpp"

namespace salient::server {
namespace {

constexpr const char* columns =
    "id, printer_id, job_id, file_digest, filename, state, confirmed, total, reason, started_at, "
    "finished_at, "
    "filament_mm, paused_seconds";

PrintRecord read_print(const Database::Statement& q) {
  PrintRecord p;
  p.id = q.integer(0);
  p.printer_id = q.text(1);
  if (!q.null(2)) p.job_id = q.text(2);
  p.file_digest = q.text(3);
  p.filename = q.text(4);
  p.state = print_state_from(q.text(5)).value_or(PrintState::failed);
  p.confirmed = q.integer(6);
  p.total = q.integer(7);
  if (!q.null(8)) p.reason = q.text(8);
  p.started_at = q.real(9);
  if (!q.null(10)) p.finished_at = q.real(10);
  p.filament_mm = q.real(11);
  p.paused_seconds = q.real(12);
  return p;
}

std::string parent_of_path(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash);
}

StoredFile read_file(const Database::Statement& q) {
  return {q.text(0), q.text(1), q.integer(2), q.real(3)};
}

}  // namespace

PrintRecord PrintStore::create(const std::string& printer_id, const std::optional<std::string>& job_id,
                               const std::string& digest, const std::string& filename, long long total,
                               double now) {
  auto q = db_.prepare(
      "INSERT INTO prints (printer_id, job_id, file_digest, filename, state, confirmed, total, "
      "started_at) "
      "VALUES (?, ?, ?, ?, 'printing', 0, ?, ?) RETURNING id");
  q.bind(1, std::string_view(printer_id))
      .bind(2, job_id)
      .bind(3, std::string_view(digest))
      .bind(4, std::string_view(filename))
      .bind(5, static_cast<std::int64_t>(total))
      .bind(6, now);
  q.step();
  const long long id = q.integer(0);
  q.run();
  return *get(id);
}

void PrintStore::set_progress(long long id, PrintState state, long long confirmed, PrintUsage usage) {
  db_.prepare(
         "UPDATE prints SET state = ?, confirmed = ?, filament_mm = ?, paused_seconds = ? "
         "WHERE id = ? AND finished_at IS NULL")
      .bind(1, to_string(state))
      .bind(2, static_cast<std::int64_t>(confirmed))
      .bind(3, usage.filament_mm)
      .bind(4, usage.paused_seconds)
      .bind(5, static_cast<std::int64_t>(id))
      .run();
}

void PrintStore::finish(long long id, PrintState state, long long confirmed,
                        const std::optional<std::string>& reason, double now, PrintUsage usage) {
  db_.prepare(
         "UPDATE prints SET state = ?, confirmed = ?, reason = ?, finished_at = ?, filament_mm = ?, "
         "paused_seconds = ? WHERE id = ?")
      .bind(1, to_string(state))
      .bind(2, static_cast<std::int64_t>(confirmed))
      .bind(3, reason)
      .bind(4, now)
      .bind(5, usage.filament_mm)
      .bind(6, usage.paused_seconds)
      .bind(7, static_cast<std::int64_t>(id))
      .run();
}

PrintTotals PrintStore::totals(const std::string& printer_id) {
  // Durations from start to end, never negative (a clock set back); CASE rather than two-argument
  // max(), which PostgreSQL spells otherwise.
  const std::string total = "CASE WHEN finished_at > started_at THEN finished_at - started_at ELSE 0 END";
  const std::string printing =
      "CASE WHEN finished_at - started_at > paused_seconds THEN finished_at - started_at - paused_seconds "
      "ELSE 0 END";
  auto q = db_.prepare(
      "SELECT count(*), "
      "count(CASE WHEN state = 'finished' THEN 1 END), count(CASE WHEN state = 'cancelled' THEN 1 END), "
      "count(CASE WHEN state = 'failed' THEN 1 END), count(CASE WHEN state = 'interrupted' THEN 1 END), "
      "coalesce(sum(" +
      total + "), 0), coalesce(sum(" + printing +
      "), 0), coalesce(sum(filament_mm), 0), "
      "coalesce(max(" +
      total + "), 0), coalesce(max(" + printing +
      "), 0) "
      "FROM prints WHERE finished_at IS NOT NULL AND (?1 = '' OR printer_id = ?1)");
  q.bind(1, std::string_view(printer_id));
  PrintTotals t;
  if (q.step()) {
    t.prints = q.integer(0), t.finished = q.integer(1), t.cancelled = q.integer(2);
    t.failed = q.integer(3), t.interrupted = q.integer(4);
    t.total_seconds = q.real(5), t.print_seconds = q.real(6), t.filament_mm = q.real(7);
    t.longest_seconds = q.real(8), t.longest_print_seconds = q.real(9);
  }
  q.run();
  return t;
}

std::optional<PrintRecord> PrintStore::get(long long id) {
  auto q = db_.prepare(std::string("SELECT ") + columns + " FROM prints WHERE id = ?");
  q.bind(1, static_cast<std::int64_t>(id));
  if (!q.step()) return std::nullopt;
  PrintRecord p = read_print(q);
  q.run();
  return p;
}

std::optional<PrintRecord> PrintStore::latest(const std::string& printer_id) {
  auto all = list(printer_id, 1);
  if (all.empty()) return std::nullopt;
  return all.front();
}

std::vector<PrintRecord> PrintStore::list(const std::string& printer_id, int limit) {
  auto q = db_.prepare(std::string("SELECT ") + columns +
                       " FROM prints WHERE printer_id = ? ORDER BY id DESC LIMIT ?");
  q.bind(1, std::string_view(printer_id)).bind(2, static_cast<std::int64_t>(limit));
  std::vector<PrintRecord> out;
  while (q.step()) out.push_back(read_print(q));
  return out;
}

int PrintStore::mark_interrupted(double now) {
  db_.prepare(
         "UPDATE prints SET state = 'interrupted', reason = 'the daemon stopped during the print', "
         "finished_at = ? "
         "WHERE finished_at IS NULL")
      .bind(1, now)
      .run();
  return db_.changes();
}

void PrintStore::put_file(const std::string& name, const std::string& digest, long long size, double now) {
  db_.prepare(
         "INSERT INTO files (name, digest, size, uploaded_at) VALUES (?, ?, ?, ?) "
         "ON CONFLICT (name) DO UPDATE SET digest = excluded.digest, size = excluded.size, uploaded_at = "
         "excluded.uploaded_at")
      .bind(1, std::string_view(name))
      .bind(2, std::string_view(digest))
      .bind(3, static_cast<std::int64_t>(size))
      .bind(4, now)
      .run();
}

std::optional<StoredFile> PrintStore::file(const std::string& name) {
  auto q = db_.prepare("SELECT name, digest, size, uploaded_at FROM files WHERE name = ?");
  q.bind(1, std::string_view(name));
  if (!q.step()) return std::nullopt;
  StoredFile f = read_file(q);
  q.run();
  return f;
}

std::vector<StoredFile> PrintStore::files() {
  auto q = db_.prepare("SELECT name, digest, size, uploaded_at FROM files ORDER BY uploaded_at DESC, name");
  std::vector<StoredFile> out;
  while (q.step()) out.push_back(read_file(q));
  return out;
}

bool PrintStore::remove_file(const std::string& name) {
  db_.prepare("DELETE FROM files WHERE name = ?").bind(1, std::string_view(name)).run();
  return db_.changes() > 0;
}

void PrintStore::put_folder(const std::string& path, double now) {
  for (std::string p = path; !p.empty(); p = parent_of_path(p))
    db_.prepare("INSERT INTO folders (path, created_at) VALUES (?, ?) ON CONFLICT (path) DO NOTHING")
        .bind(1, std::string_view(p))
        .bind(2, now)
        .run();
}

bool PrintStore::folder_exists(const std::string& path) {
  auto q = db_.prepare("SELECT 1 FROM folders WHERE path = ?");
  q.bind(1, std::string_view(path));
  const bool found = q.step();
  if (found) q.run();
  return found;
}

std::vector<std::string> PrintStore::folders() {
  auto q = db_.prepare("SELECT path FROM folders ORDER BY path");
  std::vector<std::string> out;
  while (q.step()) out.push_back(q.text(0));
  return out;
}

// "Under": the row's path starts with "FOLDER/" (compared as text, so that '%' and '_' in a
// name mean nothing, as they would to LIKE).
std::vector<StoredFile> PrintStore::remove_folder(const std::string& path) {
  Database::Transaction t(db_);
  auto q = db_.prepare(
      "SELECT name, digest, size, uploaded_at FROM files WHERE substr(name, 1, length(?1) + 1) = ?1 || '/'");
  q.bind(1, std::string_view(path));
  std::vector<StoredFile> removed;
  while (q.step()) removed.push_back(read_file(q));
  db_.prepare("DELETE FROM files WHERE substr(name, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(path))
      .run();
  db_.prepare("DELETE FROM folders WHERE path = ?1 OR substr(path, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(path))
      .run();
  t.commit();
  return removed;
}

// A queued print of a moved file follows it (the queue names files by path).
void PrintStore::move_file(const std::string& from, const std::string& to) {
  Database::Transaction t(db_);
  for (const char* sql : {"UPDATE files SET name = ?1 WHERE name = ?2",
                          "UPDATE print_queue SET ref = ?1 WHERE kind = 'file' AND ref = ?2"})
    db_.prepare(sql).bind(1, std::string_view(to)).bind(2, std::string_view(from)).run();
  t.commit();
}

void PrintStore::move_folder(const std::string& from, const std::string& to) {
  Database::Transaction t(db_);
  db_.prepare(
         "UPDATE files SET name = ?2 || substr(name, length(?1) + 1) "
         "WHERE substr(name, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(from))
      .bind(2, std::string_view(to))
      .run();
  db_.prepare(
         "UPDATE folders SET path = ?2 || substr(path, length(?1) + 1) "
         "WHERE path = ?1 OR substr(path, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(from))
      .bind(2, std::string_view(to))
      .run();
  db_.prepare(
         "UPDATE print_queue SET ref = ?2 || substr(ref, length(?1) + 1) "
         "WHERE kind = 'file' AND substr(ref, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(from))
      .bind(2, std::string_view(to))
      .run();
  t.commit();
}

void PrintStore::copy_file(const std::string& from, const std::string& to, double now) {
  db_.prepare(
         "INSERT INTO files (name, digest, size, uploaded_at) SELECT ?, digest, size, ? FROM files WHERE "
         "name = ?")
      .bind(1, std::string_view(to))
      .bind(2, now)
      .bind(3, std::string_view(from))
      .run();
}

void PrintStore::copy_folder(const std::string& from, const std::string& to, double now) {
  Database::Transaction t(db_);
  db_.prepare(
         "INSERT INTO files (name, digest, size, uploaded_at) SELECT ?2 || substr(name, length(?1) + 1), "
         "digest, size, ?3 FROM files WHERE substr(name, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(from))
      .bind(2, std::string_view(to))
      .bind(3, now)
      .run();
  db_.prepare(
         "INSERT INTO folders (path, created_at) SELECT ?2 || substr(path, length(?1) + 1), ?3 FROM folders "
         "WHERE path = ?1 OR substr(path, 1, length(?1) + 1) = ?1 || '/'")
      .bind(1, std::string_view(from))
      .bind(2, std::string_view(to))
      .bind(3, now)
      .run();
  t.commit();
}

}  // namespace salient::server
