// DataDirLock: one salientd per data directory. The daemon holds an exclusive flock(2) on
// DATA/salientd.lock for its life (the kernel drops it when the process ends, even by kill -9),
// and `salientd restore` takes the same lock, so a restore never replaces the files under a
// running daemon and a second daemon cannot start on them. A backup takes no lock: it reads
// beside the daemon (see backup.hpp).
#pragma once

#include <filesystem>
#include <optional>

namespace salient::server {

class DataDirLock {
 public:
  // Creates the directory if needed; throws StoreError naming the holder's pid when it is taken.
  explicit DataDirLock(const std::filesystem::path& data_dir);
  ~DataDirLock();
  DataDirLock(const DataDirLock&) = delete;
  DataDirLock& operator=(const DataDirLock&) = delete;

  static constexpr const char* file_name = "salientd.lock";
  // True when a process holds the lock of `data_dir` now (a probe: the lock is not kept).
  static bool held(const std::filesystem::path& data_dir);

 private:
  int fd_ = -1;
};

}  // namespace salient::server
