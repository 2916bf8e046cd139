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

}  // namespace

FileStore::FileStore(fs::path root) : root_(std::move(root)) {
  fs::create_directories(root_ / "objects");
  fs::remove_all(root_ / "tmp");
  fs::create_directories(root_ / "tmp");
}

bool FileStore::valid_digest(std::string_view d) {
  if (d.size() != 64) return false;
  for (char c : d)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

fs::path FileStore::path_of(std::string_view d) const {
  if (!valid_digest(d)) throw StoreError("not a content address: '" + std::string(d.substr(0, 80)) + "'");
  return root_ / "objects" / std::string(d.substr(0, 2)) / std::string(d.substr(2));
}

bool FileStore::contains(std::string_view d) const {
  return valid_digest(d) && fs::exists(path_of(d));
}

std::string FileStore::put(std::string_view bytes) {
  const std::string digest = sha256_hex(bytes);
  const fs::path target = path_of(digest);
  if (fs::exists(target)) return digest;  // same bytes, same name: already there
  static std::atomic<unsigned long> counter{0};
  const fs::path tmp =
      root_ / "tmp" / (digest + "." + std::to_string(::getpid()) + "." + std::to_string(counter++));
  {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw StoreError(tmp.string() + ": " + std::strerror(errno), no_space(errno));
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        const int err = errno;
        ::close(fd);
        fs::remove(tmp);
        throw StoreError(tmp.string() + ": write: " + std::strerror(err), no_space(err));
      }
      done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
      const int err = errno;
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw StoreError(tmp.string() + ": fsync: " + std::strerror(err), no_space(err));
    }
  }
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  if (!ec) fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw StoreError(target.string() + ": " + ec.message(), no_space(ec.value()));
  }
  fsync_path(target.parent_path(), O_RDONLY | O_DIRECTORY);
  return digest;
}

std::string FileStore::read(std::string_view d) const {
  std::ifstream in(path_of(d), std::ios::binary);
  if (!in) throw StoreError("no stored file " + std::string(d));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void FileStore::remove(std::string_view d) {
  fs::remove(path_of(d));
}

}  // namespace salient::server
