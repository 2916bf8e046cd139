// Database: SQLite in WAL mode, opened and migrated to the current schema (PRAGMA user_version),
// with prepared statements. One Database per thread; SQLite's locking arbitrates between them.
// No SQLite type appears here: the handle lives behind a pointer to an incomplete type.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "server/store/file_store.hpp"  // StoreError

namespace salient::server {

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
    Statement& bind_null(int index);
    Statement& bind(int index, const std::optional<std::string>& text);
    bool step();  // true: a row is ready
    void run();   // steps to the end
    std::int64_t integer(int column) const;
    double real(int column) const;
    std::string text(int column) const;
    bool null(int column) const;

   private:
    friend class Database;
    struct Impl;
    explicit Statement(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
  };

  explicit Database(const std::filesystem::path& file);  // throws StoreError
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  Statement prepare(std::string_view sql);
  void exec(std::string_view sql);
  std::int64_t last_insert_id() const;
  int changes() const;  // rows the last INSERT/UPDATE/DELETE touched
  int schema_version() const;
  static int latest_schema_version();

  // BEGIN IMMEDIATE … COMMIT, rolled back unless commit() was called.
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
  struct Handle;
  std::unique_ptr<Handle> handle_;
};

}  // namespace salient::server
