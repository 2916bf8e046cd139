#include "server/store/file_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "server/store/sha256.hpp"

namespace salient::server {
namespace {

namespace fs = std::filesystem;

bool no_space(int err) {
  return err == ENOSPC || err == EDQUOT;
}

void fsync_path(const fs::path& p, int flags) {
  const int fd = ::open(p.c_str(), flags | O_CLOEXEC);
  if (fd < 0) throw StoreError(p.string() + ": " + std::strerror(errno));
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) throw StoreError(p.string() + ": fsync: " + std::strerror(errno), no_space(errno));
}

void write_all(int fd, std::string_view bytes, const fs::path& name) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw StoreError(name.string() + ": write: " + std::strerror(errno), no_space(errno));
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

FileStore::FileStore(fs::path root, std::unique_ptr<RemoteFiles> remote)
    : root_(std::move(root)), remote_(std::move(remote)) {
  fs::create_directories(root_ / "objects");
  fs::remove_all(root_ / "tmp");
  fs::create_directories(root_ / "tmp");
}

std::optional<fs::space_info> FileStore::space() const {
  std::error_code ec;
  const fs::space_info info = fs::space(root_, ec);
  if (ec || info.capacity == static_cast<std::uintmax_t>(-1)) return std::nullopt;
  return info;
}

bool FileStore::valid_digest(std::string_view d) {
  if (d.size() != 64) return false;
  for (char c : d)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

FileStore::~FileStore() = default;

fs::path FileStore::local_path(std::string_view d) const {
  if (!valid_digest(d)) throw StoreError("not a content address: '" + std::string(d.substr(0, 80)) + "'");
  return root_ / "objects" / std::string(d.substr(0, 2)) / std::string(d.substr(2));
}

fs::path FileStore::path_of(std::string_view d) const {
  fs::path p = local_path(d);
  if (remote_ && !fs::exists(p)) fetch(d, p);
  return p;
}

bool FileStore::contains(std::string_view d) const {
  return valid_digest(d) && (fs::exists(local_path(d)) || (remote_ && remote_->has(d)));
}

std::string FileStore::put(std::string_view bytes) {
  const std::string digest = sha256_hex(bytes);
  const fs::path target = local_path(digest);
  if (!fs::exists(target)) write_local(bytes, digest, target);  // else: same bytes, same name, there
  if (remote_ && !remote_->has(digest)) remote_->upload(digest, target);
  return digest;
}

fs::path FileStore::temporary(std::string_view digest) const {
  static std::atomic<unsigned long> counter{0};
  return root_ / "tmp" /
         (std::string(digest) + "." + std::to_string(::getpid()) + "." + std::to_string(counter++));
}

void FileStore::write_local(std::string_view bytes, const std::string& digest, const fs::path& target) const {
  const fs::path tmp = temporary(digest);
  {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw StoreError(tmp.string() + ": " + std::strerror(errno), no_space(errno));
    try {
      write_all(fd, bytes, tmp);
    } catch (...) {
      ::close(fd);
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw;
    }
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
      const int err = errno;
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw StoreError(tmp.string() + ": fsync: " + std::strerror(err), no_space(err));
    }
  }
  publish(tmp, target);
}

// Renames a complete, fsynced file into place, and fsyncs the directory.
void FileStore::publish(const fs::path& tmp, const fs::path& target) const {
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  if (!ec) fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw StoreError(target.string() + ": " + ec.message(), no_space(ec.value()));
  }
  fsync_path(target.parent_path(), O_RDONLY | O_DIRECTORY);
}

// The remote copy, a chunk at a time into tmp/, checked against its name before it is published:
// a copy cut short (removed meanwhile, a lost connection) never enters the cache.
void FileStore::fetch(std::string_view d, const fs::path& target) const {
  const fs::path tmp = temporary(d);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw StoreError(tmp.string() + ": " + std::strerror(errno), no_space(errno));
  Sha256 sha;
  bool found = false;
  try {
    found = remote_->download(d, [&](std::string_view chunk) {
      sha.update(chunk);
      write_all(fd, chunk, tmp);
    });
  } catch (...) {
    ::close(fd);
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  const bool synced = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!found || !synced || sha.hex() != d) {
    fs::remove(tmp);
    if (!found) return;  // no such file: the caller finds no file at the path, as without a remote
    if (!synced) throw StoreError(tmp.string() + ": fsync: " + std::strerror(err), no_space(err));
    throw StoreError("stored file " + std::string(d) + " came back with other bytes");
  }
  publish(tmp, target);
}

std::string FileStore::read(std::string_view d) const {
  std::ifstream in(path_of(d), std::ios::binary);
  if (!in) throw StoreError("no stored file " + std::string(d));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void FileStore::remove(std::string_view d) {
  fs::remove(local_path(d));
  if (remote_) remote_->remove(d);
}

}  // namespace salient::server
