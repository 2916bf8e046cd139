// FileStore: content-addressed files under a directory: objects/<2 hex>/<62 hex>, named by the
// SHA-256 of their bytes. A write goes to tmp/, is fsynced, then renamed into place (and the
// directory fsynced), so a reader never sees half a file, even after a crash.
//
// With a RemoteFiles (PostgreSQL's blobs, for a farm whose nodes share no disk) the remote copy
// is the truth and the directory a cache of it on this node: put() stores both; path_of() and
// read() fetch a file missing here, streamed a chunk at a time and checked against its digest.
// Files never change, so a cached copy is never stale; callers keep the paths they get.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
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

// Where files live beside this node's disk. Chunks go through the callbacks: no whole file in memory.
class RemoteFiles {
 public:
  virtual ~RemoteFiles() = default;
  virtual bool has(std::string_view digest) = 0;
  // Stores the file at `file` under `digest` (nothing if it is there already), atomically.
  virtual void upload(std::string_view digest, const std::filesystem::path& file) = 0;
  // Hands the bytes to `sink` in order; false if there is no such file.
  virtual bool download(std::string_view digest, const std::function<void(std::string_view)>& sink) = 0;
  virtual void remove(std::string_view digest) = 0;
};

class FileStore {
 public:
  // Creates `root`; clears tmp/ (interrupted writes).
  explicit FileStore(std::filesystem::path root, std::unique_ptr<RemoteFiles> remote = nullptr);
  ~FileStore();

  std::string put(std::string_view bytes);  // returns the digest (64 hex digits)
  bool contains(std::string_view digest) const;
  // Throws StoreError on a bad digest. With a remote, fetches the file into the cache first.
  std::filesystem::path path_of(std::string_view digest) const;
  std::string read(std::string_view digest) const;
  void remove(std::string_view digest);

  static bool valid_digest(std::string_view digest);
  // Bytes free (for this process) and in all on the file system holding the files; none if it
  // cannot be read.
  std::optional<std::filesystem::space_info> space() const;

 private:
  std::filesystem::path local_path(std::string_view digest) const;
  std::filesystem::path temporary(std::string_view digest) const;
  void write_local(std::string_view bytes, const std::string& digest,
                   const std::filesystem::path& target) const;
  void publish(const std::filesystem::path& tmp, const std::filesystem::path& target) const;
  void fetch(std::string_view digest, const std::filesystem::path& target) const;
  std::filesystem::path root_;
  std::unique_ptr<RemoteFiles> remote_;
};

}  // namespace salient::server
