// Database: one connection to the store, SQLite or PostgreSQL (DatabaseUrl), opened and migrated
// to the current schema, with prepared statements. One Database per thread: SQLite's locking, or
// PostgreSQL's, arbitrates between them. SQL is written once for both: "?"/"?N" placeholders,
// INSERT … ON CONFLICT, RETURNING; what differs is behind the backend (database_backend.hpp).
// No SQLite or libpq type appears here.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "server/store/database_url.hpp"
#include "server/store/file_store.hpp"  // StoreError

namespace salient::server {

namespace detail {
class DatabaseBackend;
class StatementBackend;
}  // namespace detail

class Database {
 public:
  class Statement {
   public:
    ~Statement();
    Statement(Statement&&) noexcept;
    Statement& operator=(Statement&&) = delete;

    Statement& bind(int index, std::int64_t value);
    Statement& bind(int index, double value);
    Statement& bind(int index, std::string_view text);
    Statement& bind_blob(int index, std::string_view bytes);  // BLOB / BYTEA
    Statement& bind_null(int index);
    Statement& bind(int index, const std::optional<std::string>& text);
    bool step();  // true: a row is ready
    void run();   // steps to the end
    std::int64_t integer(int column) const;
    double real(int column) const;
    std::string text(int column) const;
    std::string blob(int column) const;
    bool null(int column) const;

   private:
    friend class Database;
    explicit Statement(std::unique_ptr<detail::StatementBackend> impl);
    std::unique_ptr<detail::StatementBackend> impl_;
  };

  explicit Database(const DatabaseUrl& url);             // throws StoreError
  explicit Database(const std::filesystem::path& file);  // a SQLite file
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  Dialect dialect() const;
  Statement prepare(std::string_view sql);
  void exec(std::string_view sql);
  // Prefer "INSERT … RETURNING id": on PostgreSQL this costs a round trip more.
  std::int64_t last_insert_id() const;
  int changes() const;  // rows the last INSERT/UPDATE/DELETE touched
  bool in_transaction() const;
  int schema_version() const;
  static int latest_schema_version();

  // Notifications between the nodes of a PostgreSQL store (NOTIFY/LISTEN). `channel`: lower-case
  // letters, digits and '_', at most 63; `payload`: shorter than 8000 bytes (PostgreSQL's limit).
  // notify() runs on this connection, so inside an open transaction it is sent at its commit and
  // not at all on rollback. A SQLite store has one node and nothing to notify: these throw
  // StoreError there (a caller that forgot to check the dialect hears of it).
  static constexpr std::size_t kMaxNotifyPayload = 7999;
  struct Notification {
    std::string channel, payload;
  };
  void notify(std::string_view channel, std::string_view payload);
  void listen(std::string_view channel);  // this connection then receives the channel's notifications
  // The next notification for a channel this connection listens to, waiting up to `timeout`;
  // nothing if none came. Throws StoreError if the connection broke: LISTEN went with it, so the
  // caller opens a new Database and listens again.
  std::optional<Notification> wait_notification(std::chrono::milliseconds timeout);

  // A write transaction, rolled back unless commit() was called. Writers wait for each other
  // (SQLite: BEGIN IMMEDIATE; PostgreSQL: BEGIN and an advisory lock), so that a read then a
  // write inside one sees no other writer in between.
  class Transaction {
   public:
    explicit Transaction(Database& db);
    ~Transaction();
    void commit();

   private:
    Database& db_;
    bool done_ = false;
  };

 private:
  void migrate();
  std::unique_ptr<detail::DatabaseBackend> backend_;
};

// A statement written once for both dialects, with tokens: {NOW} the database's clock (seconds
// since the epoch, with fractions: one clock for every node of a farm, whatever the hosts' clocks
// say), {REAL}, and {SKIP_LOCKED}, which on PostgreSQL lets concurrent claimers pass over a row
// another one is taking (SQLite has one writer at a time and needs nothing).
std::string dialect_sql(const Database& db, std::string sql);

}  // namespace salient::server
