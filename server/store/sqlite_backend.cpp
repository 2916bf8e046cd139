// The SQLite backend: WAL mode, prepared statements, PRAGMA user_version as the schema version.
#include <sqlite3.h>

#include <filesystem>

#include "server/store/database_backend.hpp"
#include "server/store/file_store.hpp"  // StoreError

namespace salient::server::detail {
namespace {

bool full(int rc) {
  return (rc & 0xff) == SQLITE_FULL;
}

[[noreturn]] void no_notifications() {
  throw StoreError("notifications between nodes need a PostgreSQL store; SQLite has one node");
}

class SqliteStatement final : public StatementBackend {
 public:
  SqliteStatement(sqlite3* db, sqlite3_stmt* stmt) : db_(db), stmt_(stmt) {}
  ~SqliteStatement() override { sqlite3_finalize(stmt_); }

  void bind_integer(int i, std::int64_t v) override { check(sqlite3_bind_int64(stmt_, i, v)); }
  void bind_real(int i, double v) override { check(sqlite3_bind_double(stmt_, i, v)); }
  void bind_text(int i, std::string_view t) override {
    check(sqlite3_bind_text64(stmt_, i, t.data(), t.size(), SQLITE_TRANSIENT, SQLITE_UTF8));
  }
  void bind_blob(int i, std::string_view b) override {
    check(sqlite3_bind_blob64(stmt_, i, b.data(), b.size(), SQLITE_TRANSIENT));
  }
  void bind_null(int i) override { check(sqlite3_bind_null(stmt_, i)); }

  bool step() override {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) {
      sqlite3_reset(stmt_);
      return false;
    }
    const std::string message = sqlite3_errmsg(db_);
    sqlite3_reset(stmt_);
    throw StoreError("SQLite: " + message, full(rc));
  }

  std::int64_t integer(int c) const override { return sqlite3_column_int64(stmt_, c); }
  double real(int c) const override { return sqlite3_column_double(stmt_, c); }
  bool null(int c) const override { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
  std::string text(int c) const override {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, c));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(stmt_, c))) : std::string();
  }
  std::string blob(int c) const override {
    const auto* p = static_cast<const char*>(sqlite3_column_blob(stmt_, c));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(stmt_, c))) : std::string();
  }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) throw StoreError(std::string("bind: ") + sqlite3_errmsg(db_), full(rc));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_;
};

class SqliteBackend final : public DatabaseBackend {
 public:
  explicit SqliteBackend(const std::string& file) {
    const std::filesystem::path path(file);
    if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
    if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                        nullptr) != SQLITE_OK)
      throw StoreError(file + ": " + (db_ ? sqlite3_errmsg(db_) : "out of memory"));
    sqlite3_busy_timeout(db_, 5000);
    // WAL: readers never block the writer; synchronous=NORMAL is durable at each checkpoint and
    // never corrupts (SQLite's recommendation for WAL).
    exec("PRAGMA journal_mode = WAL; PRAGMA synchronous = NORMAL; PRAGMA foreign_keys = ON;");
  }
  ~SqliteBackend() override { sqlite3_close_v2(db_); }

  Dialect dialect() const override { return Dialect::sqlite; }

  std::unique_ptr<StatementBackend> prepare(std::string_view sql) override {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt, nullptr) != SQLITE_OK)
      throw StoreError("SQL error in \"" + std::string(sql.substr(0, 60)) + "\": " + sqlite3_errmsg(db_));
    return std::make_unique<SqliteStatement>(db_, stmt);
  }

  void exec(std::string_view sql) override {
    char* error = nullptr;
    if (const int rc = sqlite3_exec(db_, std::string(sql).c_str(), nullptr, nullptr, &error);
        rc != SQLITE_OK) {
      const std::string message = error ? error : "unknown error";
      sqlite3_free(error);
      throw StoreError("SQLite: " + message, full(rc));
    }
  }

  std::int64_t last_insert_id() override { return sqlite3_last_insert_rowid(db_); }
  int changes() const override { return sqlite3_changes(db_); }
  bool in_transaction() const override { return sqlite3_get_autocommit(db_) == 0; }

  int schema_version() override {
    sqlite3_stmt* stmt = nullptr;
    sqlite3_prepare_v2(db_, "PRAGMA user_version", -1, &stmt, nullptr);
    const int v = sqlite3_step(stmt) == SQLITE_ROW ? sqlite3_column_int(stmt, 0) : 0;
    sqlite3_finalize(stmt);
    return v;
  }
  void set_schema_version(int version) override { exec("PRAGMA user_version = " + std::to_string(version)); }
  // IMMEDIATE: takes the write lock now, so that a transaction never fails half-way on a busy
  // database (the busy timeout waits for it instead).
  void begin_write() override { exec("BEGIN IMMEDIATE"); }
  // One SQLite store is one node: there is nobody to notify. An error rather than a silent no-op,
  // so that a caller that forgot to check the dialect does not lose its events unseen.
  void notify(std::string_view, std::string_view) override { no_notifications(); }
  void listen(std::string_view) override { no_notifications(); }
  std::optional<std::pair<std::string, std::string>> wait_notification(int) override { no_notifications(); }

 private:
  sqlite3* db_ = nullptr;
};

}  // namespace

std::unique_ptr<DatabaseBackend> open_sqlite(const std::string& file) {
  return std::make_unique<SqliteBackend>(file);
}

}  // namespace salient::server::detail
