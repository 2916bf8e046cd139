#include "server/store/database.hpp"

#include <sqlite3.h>

#include <vector>

namespace salient::server {
namespace {

// Each entry moves the schema from version i to i + 1. Never edit one that has shipped: add another.
const std::vector<const char*> migrations = {
    R"sql(
CREATE TABLE jobs (
  id TEXT PRIMARY KEY,
  state TEXT NOT NULL CHECK (state IN ('queued', 'running', 'done', 'failed', 'cancelled')),
  phase TEXT,
  progress REAL NOT NULL DEFAULT 0,
  filename TEXT NOT NULL,
  model_digest TEXT NOT NULL,
  settings TEXT NOT NULL,
  settings_digest TEXT NOT NULL,
  error TEXT,
  result TEXT,
  attempts INTEGER NOT NULL DEFAULT 0,
  created_at REAL NOT NULL,
  started_at REAL,
  finished_at REAL
);
CREATE INDEX jobs_by_state ON jobs (state, created_at);
CREATE INDEX jobs_by_content ON jobs (model_digest, settings_digest, state);
CREATE TABLE printers (
  id TEXT PRIMARY KEY,
  config TEXT NOT NULL,
  updated_at REAL NOT NULL
);
CREATE TABLE prints (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  printer_id TEXT NOT NULL,
  job_id TEXT REFERENCES jobs (id) ON DELETE SET NULL,
  file_digest TEXT NOT NULL,
  filename TEXT NOT NULL,
  state TEXT NOT NULL,
  confirmed INTEGER NOT NULL DEFAULT 0,
  total INTEGER NOT NULL,
  reason TEXT,
  started_at REAL NOT NULL,
  finished_at REAL
);
CREATE INDEX prints_by_printer ON prints (printer_id, started_at);
CREATE TABLE api_keys (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  key_digest TEXT NOT NULL UNIQUE,
  label TEXT NOT NULL,
  created_at REAL NOT NULL
);
)sql",
    // 2: files uploaded to print (OctoPrint's /api/files/local), by name.
    R"sql(
CREATE TABLE files (
  name TEXT PRIMARY KEY,
  digest TEXT NOT NULL,
  size INTEGER NOT NULL,
  uploaded_at REAL NOT NULL
);
)sql",
    // 3: each printer's print queue: requests that found the printer busy, waiting their turn.
    R"sql(
CREATE TABLE print_queue (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  printer_id TEXT NOT NULL,
  kind TEXT NOT NULL CHECK (kind IN ('job', 'file')),
  ref TEXT NOT NULL,
  position INTEGER NOT NULL,
  created_at REAL NOT NULL
);
CREATE INDEX print_queue_by_printer ON print_queue (printer_id, position);
)sql",
    // 4: users with roles; every key belongs to one. The keys made before (hex, the first
    // start's) belong to the user 'admin', who is an admin.
    R"sql(
CREATE TABLE users (
  name TEXT PRIMARY KEY,
  role TEXT NOT NULL CHECK (role IN ('admin', 'operator', 'viewer')),
  created_at REAL NOT NULL
);
INSERT INTO users (name, role, created_at)
  VALUES ('admin', 'admin', COALESCE((SELECT MIN(created_at) FROM api_keys), CAST(strftime('%s', 'now') AS REAL)));
ALTER TABLE api_keys ADD COLUMN user TEXT NOT NULL DEFAULT 'admin';
CREATE INDEX api_keys_by_user ON api_keys (user);
)sql",
    // 5: folders of uploaded files (files.name is a path "a/b/c.gcode" inside them), and the
    // settings OctoPrint clients write (POST /api/settings), by key.
    R"sql(
CREATE TABLE folders (
  path TEXT PRIMARY KEY,
  created_at REAL NOT NULL
);
CREATE TABLE settings (
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL,
  updated_at REAL NOT NULL
);
)sql",
};

}  // namespace

struct Database::Handle {
  sqlite3* db = nullptr;
  ~Handle() { sqlite3_close_v2(db); }
  [[noreturn]] void fail(std::string_view what) const {
    throw StoreError(std::string(what) + ": " + (db ? sqlite3_errmsg(db) : "out of memory"));
  }
};

struct Database::Statement::Impl {
  sqlite3* db;
  sqlite3_stmt* stmt;
  ~Impl() { sqlite3_finalize(stmt); }
  void check(int rc, std::string_view what) const {
    if (rc != SQLITE_OK)
      throw StoreError(std::string(what) + ": " + sqlite3_errmsg(db), (rc & 0xff) == SQLITE_FULL);
  }
};

Database::Statement::Statement(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Database::Statement::Statement(Statement&&) noexcept = default;
Database::Statement::~Statement() = default;

Database::Statement& Database::Statement::bind(int i, std::int64_t v) {
  impl_->check(sqlite3_bind_int64(impl_->stmt, i, v), "bind");
  return *this;
}
Database::Statement& Database::Statement::bind(int i, double v) {
  impl_->check(sqlite3_bind_double(impl_->stmt, i, v), "bind");
  return *this;
}
Database::Statement& Database::Statement::bind(int i, std::string_view t) {
  impl_->check(sqlite3_bind_text64(impl_->stmt, i, t.data(), t.size(), SQLITE_TRANSIENT, SQLITE_UTF8),
               "bind");
  return *this;
}
Database::Statement& Database::Statement::bind_null(int i) {
  impl_->check(sqlite3_bind_null(impl_->stmt, i), "bind");
  return *this;
}
Database::Statement& Database::Statement::bind(int i, const std::optional<std::string>& t) {
  return t ? bind(i, std::string_view(*t)) : bind_null(i);
}

bool Database::Statement::step() {
  const int rc = sqlite3_step(impl_->stmt);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) {
    sqlite3_reset(impl_->stmt);
    return false;
  }
  const std::string message = sqlite3_errmsg(impl_->db);
  sqlite3_reset(impl_->stmt);
  throw StoreError("SQLite: " + message, (rc & 0xff) == SQLITE_FULL);
}

void Database::Statement::run() {
  while (step()) {
  }
}

std::int64_t Database::Statement::integer(int c) const {
  return sqlite3_column_int64(impl_->stmt, c);
}
double Database::Statement::real(int c) const {
  return sqlite3_column_double(impl_->stmt, c);
}
bool Database::Statement::null(int c) const {
  return sqlite3_column_type(impl_->stmt, c) == SQLITE_NULL;
}
std::string Database::Statement::text(int c) const {
  const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(impl_->stmt, c));
  return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(impl_->stmt, c))) : std::string();
}

Database::Database(const std::filesystem::path& file) : handle_(std::make_unique<Handle>()) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  if (sqlite3_open_v2(file.c_str(), &handle_->db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK)
    handle_->fail(file.string());
  sqlite3_busy_timeout(handle_->db, 5000);
  // WAL: readers never block the writer; synchronous=NORMAL is durable at each checkpoint and
  // never corrupts (SQLite's recommendation for WAL).
  exec("PRAGMA journal_mode = WAL; PRAGMA synchronous = NORMAL; PRAGMA foreign_keys = ON;");
  migrate();
}

Database::~Database() = default;

Database::Statement Database::prepare(std::string_view sql) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(handle_->db, sql.data(), static_cast<int>(sql.size()), &stmt, nullptr) != SQLITE_OK)
    handle_->fail("SQL error in \"" + std::string(sql.substr(0, 60)) + "\"");
  return Statement(std::unique_ptr<Statement::Impl>(new Statement::Impl{handle_->db, stmt}));
}

void Database::exec(std::string_view sql) {
  char* error = nullptr;
  if (const int rc = sqlite3_exec(handle_->db, std::string(sql).c_str(), nullptr, nullptr, &error);
      rc != SQLITE_OK) {
    const std::string message = error ? error : "unknown error";
    sqlite3_free(error);
    throw StoreError("SQLite: " + message, (rc & 0xff) == SQLITE_FULL);
  }
}

std::int64_t Database::last_insert_id() const {
  return sqlite3_last_insert_rowid(handle_->db);
}
int Database::changes() const {
  return sqlite3_changes(handle_->db);
}

int Database::schema_version() const {
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(handle_->db, "PRAGMA user_version", -1, &stmt, nullptr);
  int v = sqlite3_step(stmt) == SQLITE_ROW ? sqlite3_column_int(stmt, 0) : 0;
  sqlite3_finalize(stmt);
  return v;
}

int Database::latest_schema_version() {
  return static_cast<int>(migrations.size());
}

void Database::migrate() {
  if (schema_version() == latest_schema_version()) return;
  Transaction t(*this);  // BEGIN IMMEDIATE: another process migrating waits here, then finds it done
  const int have = schema_version();
  if (have > latest_schema_version())
    // A downgrade: the older code would misread the newer tables. Nothing is written.
    throw StoreError("the database has schema version " + std::to_string(have) +
                     ", newer than this salientd (" + std::to_string(latest_schema_version()) +
                     "): a newer salientd wrote it. Refusing to open it rather than risk damaging "
                     "it: install the newer salientd again, or restore a backup made by this version");
  for (int v = have; v < latest_schema_version(); ++v) exec(migrations[static_cast<std::size_t>(v)]);
  exec("PRAGMA user_version = " + std::to_string(latest_schema_version()));
  t.commit();
}

Database::Transaction::Transaction(Database& db) : db_(db) {
  db_.exec("BEGIN IMMEDIATE");
}
Database::Transaction::~Transaction() {
  if (!done_) {
    try {
      db_.exec("ROLLBACK");
    } catch (...) {
    }
  }
}
void Database::Transaction::commit() {
  db_.exec("COMMIT");
  done_ = true;
}

}  // namespace salient::server
