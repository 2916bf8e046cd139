// Store: the daemon's data directory: the SQLite database (one connection per thread, as SQLite
// wants) and the content-addressed files.
#pragma once

#include <filesystem>

#include "server/store/database.hpp"
#include "server/store/file_store.hpp"

namespace salient::server {

class Store {
 public:
  explicit Store(const std::filesystem::path& data_dir);  // creates and migrates; throws StoreError

  Database& db();  // the calling thread's connection
  FileStore& files() { return files_; }
  const std::filesystem::path& data_dir() const { return dir_; }

 private:
  std::filesystem::path dir_, db_path_;
  FileStore files_;
};

}  // namespace salient::server
