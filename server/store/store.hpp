// Store: the daemon's data directory: the SQLite database (one connection per thread, as SQLite
// wants) and the content-addressed files.
#pragma once

#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "server/store/database.hpp"
#include "server/store/file_store.hpp"

namespace salient::server {

class Store {
 public:
  explicit Store(const std::filesystem::path& data_dir);  // creates and migrates; throws StoreError

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

 private:
  std::filesystem::path dir_, db_path_;
  FileStore files_;
  std::mutex files_mutex_;
};

}  // namespace salient::server
