// DatabaseUrl: which store backend a daemon uses, from one string: a path or "sqlite:PATH" is a
// SQLite file, "postgresql://…" or "postgres://…" a PostgreSQL database (libpq's URI syntax).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace salient::server {

enum class Dialect { sqlite, postgresql };

struct DatabaseUrl {
  Dialect dialect = Dialect::sqlite;
  std::string target;  // the file path (SQLite) or the whole URI (PostgreSQL)

  static DatabaseUrl sqlite(const std::filesystem::path& file) { return {Dialect::sqlite, file.string()}; }
  // Throws StoreError on an empty string or an unknown scheme ("mysql://…").
  static DatabaseUrl parse(std::string_view text);
  // For logs: the URI without its password.
  std::string redacted() const;
};

}  // namespace salient::server
