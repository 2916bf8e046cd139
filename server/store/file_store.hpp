// FileStore: content-addressed files under a directory: objects/<2 hex>/<62 hex>, named by the
// SHA-256 of their bytes. A write goes to tmp/, is fsynced, then renamed into place (and the
// directory fsynced), so a reader never sees half a file, even after a crash.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace salient::server {

// What went wrong in the data directory. disk_full(): no space (ENOSPC, EDQUOT, SQLITE_FULL):
// the operation fails with 507 and the daemon carries on; space may come back.
class StoreError : public std::runtime_error {
 public:
  explicit StoreError(const std::string& message, bool disk_full = false)
      : std::runtime_error(message), disk_full_(disk_full) {}
  bool disk_full() const { return disk_full_; }

 private:
  bool disk_full_;
};

class FileStore {
 public:
  explicit FileStore(std::filesystem::path root);  // creates it; clears tmp/ (interrupted writes)

  std::string put(std::string_view bytes);  // returns the digest (64 hex digits)
  bool contains(std::string_view digest) const;
  std::filesystem::path path_of(std::string_view digest) const;  // throws StoreError on a bad digest
  std::string read(std::string_view digest) const;
  void remove(std::string_view digest);

  static bool valid_digest(std::string_view digest);

 private:
  std::filesystem::path root_;
};

}  // namespace salient::server
