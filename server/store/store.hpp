// Store: the daemon's data: the database (SQLite in the data directory by default, or the one a
// DatabaseUrl names; one connection per thread) and the content-addressed files (in the data
// directory; with PostgreSQL in the database too, the directory then being this node's cache,
// unless a directory the nodes share is given).
#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/store/database.hpp"
#include "server/store/file_store.hpp"

namespace salient::server {

class Store {
 public:
  // Creates and migrates; throws StoreError. No URL: SQLite, DATA_DIR/salient.db. `shared_files`:
  // files there (and not in PostgreSQL).
  explicit Store(const std::filesystem::path& data_dir, std::optional<DatabaseUrl> url = std::nullopt,
                 const std::filesystem::path& shared_files = {});

  Database& db();  // the calling thread's connection
  FileStore& files() { return files_; }

  // Removes those of `digests` that no job, print or uploaded file refers to any more (the rows
  // that referred to them are gone); returns how many. Content-addressed files are shared, so a
  // file goes only when its last reference does.
  std::size_t remove_unreferenced(const std::vector<std::string>& digests);
  // Held from storing a file to writing the row that refers to it, so that a sweep cannot take
  // the file in between.
  std::mutex& files_mutex() { return files_mutex_; }
  const std::filesystem::path& data_dir() const { return dir_; }
  const DatabaseUrl& database_url() const { return url_; }

 private:
  std::filesystem::path dir_;
  DatabaseUrl url_;
  // Its threads' connections live while this does (see db()); before files_, which may use them.
  std::shared_ptr<const char> alive_ = std::make_shared<const char>(0);
  FileStore files_;
  std::mutex files_mutex_;
};

}  // namespace salient::server
