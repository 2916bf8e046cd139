// The interface each store backend implements behind Database (SQLite, PostgreSQL). Internal to
// server/store: Database is what the rest of the daemon sees. Parameters are numbered from 1,
// columns from 0, as in Database::Statement.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "server/store/database_url.hpp"

namespace salient::server::detail {

class StatementBackend {
 public:
  virtual ~StatementBackend() = default;
  virtual void bind_integer(int index, std::int64_t value) = 0;
  virtual void bind_real(int index, double value) = 0;
  virtual void bind_text(int index, std::string_view text) = 0;
  virtual void bind_blob(int index, std::string_view bytes) = 0;
  virtual void bind_null(int index) = 0;
  // Runs the statement on its first call, then moves through the rows; false at the end, when
  // the statement is reset (the bindings stay) and may run again.
  virtual bool step() = 0;
  virtual std::int64_t integer(int column) const = 0;
  virtual double real(int column) const = 0;
  virtual std::string text(int column) const = 0;
  virtual std::string blob(int column) const = 0;
  virtual bool null(int column) const = 0;
};

class DatabaseBackend {
 public:
  virtual ~DatabaseBackend() = default;
  virtual Dialect dialect() const = 0;
  virtual std::unique_ptr<StatementBackend> prepare(std::string_view sql) = 0;
  virtual void exec(std::string_view sql) = 0;  // one or more statements, no parameters
  virtual std::int64_t last_insert_id() = 0;
  virtual int changes() const = 0;
  virtual bool in_transaction() const = 0;
  virtual int schema_version() = 0;
  virtual void set_schema_version(int version) = 0;  // inside the migration's transaction
  // A write transaction that excludes other writers, as SQLite's BEGIN IMMEDIATE does.
  virtual void begin_write() = 0;
  // Notifications between connections (PostgreSQL's NOTIFY/LISTEN); SQLite throws StoreError.
  virtual void notify(std::string_view channel, std::string_view payload) = 0;
  virtual void listen(std::string_view channel) = 0;
  // Waits up to `timeout_ms` for one notification (channel, payload); throws StoreError if the
  // connection broke.
  virtual std::optional<std::pair<std::string, std::string>> wait_notification(int timeout_ms) = 0;
};

std::unique_ptr<DatabaseBackend> open_sqlite(const std::string& file);
std::unique_ptr<DatabaseBackend> open_postgresql(const std::string& url);

}  // namespace salient::server::detail
