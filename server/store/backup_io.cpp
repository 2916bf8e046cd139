#include "server/store/backup_io.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "server/store/file_store.hpp"  // StoreError
#include "server/store/sha256.hpp"

namespace salient::server::backup_io {
namespace {

bool no_space(int err) {
  return err == ENOSPC || err == EDQUOT;
}

[[noreturn]] void fail_errno(const fs::path& p, const std::string& what, int err) {
  throw StoreError(p.string() + ": " + what + std::strerror(err), no_space(err));
}

struct Closer {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
using Connection = std::unique_ptr<sqlite3, Closer>;

// Read-only: a backup never writes the daemon's database, and opening it so creates no -wal or
// -shm owned by whoever runs the backup (root, say) that the daemon's user could not open later.
Connection open_read_only(const fs::path& db) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(db.c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr);
  Connection c(raw);
  if (rc != SQLITE_OK) throw StoreError(db.string() + ": " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  sqlite3_busy_timeout(raw, 10000);
  return c;
}

// The rows of a one-column query as text; SQLite's error as a StoreError.
std::vector<std::string> column(sqlite3* db, const fs::path& where, const std::string& sql) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK)
    throw StoreError(where.string() + ": " + sqlite3_errmsg(db));
  std::vector<std::string> rows;
  int rc;
  while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
    if (p) rows.emplace_back(p, static_cast<std::size_t>(sqlite3_column_bytes(stmt, 0)));
  }
  sqlite3_finalize(stmt);
  if (rc != SQLITE_DONE) throw StoreError(where.string() + ": " + sqlite3_errmsg(db));
  return rows;
}

bool is_hex(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
}

// Every run of exactly 64 lower-case hex digits: a job's result names its artefacts by digest
// inside JSON (as Store::remove_unreferenced reads it), and nothing else in it is that long.
void digests_in(const std::string& text, std::set<std::string>& out) {
  std::size_t i = 0;
  while (i < text.size()) {
    if (!is_hex(text[i])) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && is_hex(text[j])) ++j;
    if (j - i == 64) out.insert(text.substr(i, 64));
    i = j;
  }
}

void write_all(int fd, const fs::path& p, const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail_errno(p, "write: ", errno);
    done += static_cast<std::size_t>(n);
  }
}

// Streams `source` into a new `dest` (fsynced), hashing on the way; the hex digest, or nullopt
// when the source does not exist.
std::optional<std::string> copy_hashing(const fs::path& source, const fs::path& dest, mode_t mode) {
  // Never through a link, never a FIFO or device: a backup or restore run as root copies only
  // the plain file that is there (O_NONBLOCK: opening a FIFO does not wait for a writer).
  const int in = ::open(source.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (in < 0 && errno == ENOENT) return std::nullopt;
  if (in < 0 && errno == ELOOP) throw StoreError(source.string() + " is a symbolic link: refused");
  if (in < 0) fail_errno(source, "", errno);
  struct stat st {};
  if (::fstat(in, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(in);
    throw StoreError(source.string() + " is not a regular file: refused");
  }
  const int out = ::open(dest.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  if (out < 0) {
    const int err = errno;
    ::close(in);
    fail_errno(dest, "", err);
  }
  Sha256 hash;
  std::vector<char> buf(1 << 16);
  try {
    for (;;) {
      const ssize_t n = ::read(in, buf.data(), buf.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) fail_errno(source, "read: ", errno);
      if (n == 0) break;
      hash.update(std::string_view(buf.data(), static_cast<std::size_t>(n)));
      write_all(out, dest, buf.data(), static_cast<std::size_t>(n));
    }
    if (::fsync(out) != 0) fail_errno(dest, "fsync: ", errno);
  } catch (...) {
    ::close(in);
    ::close(out);
    throw;
  }
  ::close(in);
  if (::close(out) != 0) fail_errno(dest, "close: ", errno);
  return hash.hex();
}

}  // namespace

void snapshot_database(const fs::path& source, const fs::path& dest) {
  if (!fs::is_regular_file(source)) throw StoreError(source.string() + ": no database here");
  Connection from = open_read_only(source);
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(dest.c_str(), &raw,
                                 SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  Connection to(raw);
  if (rc != SQLITE_OK) throw StoreError(dest.string() + ": " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  sqlite3_backup* b = sqlite3_backup_init(to.get(), "main", from.get(), "main");
  if (!b) throw StoreError(dest.string() + ": " + sqlite3_errmsg(to.get()));
  // All pages in one step: one read transaction, so one consistent state. The daemon's writer
  // is never blocked by it (WAL); a checkpoint in progress may answer BUSY for a moment.
  int step;
  for (int tries = 0; (step = sqlite3_backup_step(b, -1)) == SQLITE_BUSY || step == SQLITE_LOCKED; ++tries) {
    if (tries > 200) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  sqlite3_backup_finish(b);
  if (step != SQLITE_DONE)
    throw StoreError(dest.string() + ": database snapshot: " + sqlite3_errstr(step),
                     (step & 0xff) == SQLITE_FULL);
  if (const int e = sqlite3_errcode(to.get()); e != SQLITE_OK)
    throw StoreError(dest.string() + ": database snapshot: " + sqlite3_errmsg(to.get()),
                     (e & 0xff) == SQLITE_FULL);
  // A standalone file: rollback journal, so that reading it never needs a -wal or -shm beside it
  // (the daemon turns WAL on again when it opens a restored copy).
  sqlite3_exec(to.get(), "PRAGMA journal_mode = DELETE", nullptr, nullptr, nullptr);
  to.reset();
  const int fd = ::open(dest.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) fail_errno(dest, "fsync: ", errno);
  ::close(fd);
}

std::set<std::string> referenced_digests(const fs::path& db) {
  Connection c = open_read_only(db);
  std::set<std::string> tables;
  for (std::string& t : column(c.get(), db, "SELECT name FROM sqlite_master WHERE type = 'table'"))
    tables.insert(std::move(t));
  // Older schemas lack some tables: a backup of schema 1 has no uploads.
  std::vector<std::string> queries;
  if (tables.count("jobs")) {
    queries.push_back("SELECT model_digest FROM jobs");
    queries.push_back("SELECT result FROM jobs WHERE result IS NOT NULL");
  }
  if (tables.count("prints")) queries.push_back("SELECT file_digest FROM prints");
  if (tables.count("files")) queries.push_back("SELECT digest FROM files");
  std::set<std::string> out;
  for (const std::string& q : queries)
    for (const std::string& text : column(c.get(), db, q)) digests_in(text, out);
  return out;
}

std::string integrity_check(const fs::path& db) {
  Connection c = open_read_only(db);
  std::string found;
  for (const std::string& line : column(c.get(), db, "PRAGMA integrity_check"))
    found += (found.empty() ? "" : "; ") + line;
  return found;
}

int schema_version(const fs::path& db) {
  Connection c = open_read_only(db);
  const std::vector<std::string> v = column(c.get(), db, "PRAGMA user_version");
  return v.empty() ? 0 : std::stoi(v.front());
}

fs::path object_path(const fs::path& root, std::string_view d) {
  if (!FileStore::valid_digest(d))
    throw StoreError("not a content address: '" + std::string(d.substr(0, 80)) + "'");
  return root / "files" / "objects" / std::string(d.substr(0, 2)) / std::string(d.substr(2));
}

bool copy_object(const fs::path& source, const fs::path& dest, std::string_view digest) {
  std::error_code ec;
  fs::create_directories(dest.parent_path(), ec);
  if (ec) throw StoreError(dest.parent_path().string() + ": " + ec.message(), no_space(ec.value()));
  const std::optional<std::string> got = copy_hashing(source, dest, 0644);
  if (!got) return false;
  if (*got != digest) {
    fs::remove(dest, ec);
    throw StoreError(source.string() + ": damaged: its bytes hash to " + got->substr(0, 12) +
                     "…, not to its name " + std::string(digest.substr(0, 12)) + "…");
  }
  return true;
}

std::string file_sha256(const fs::path& file) {
  const int in = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) fail_errno(file, "", errno);
  Sha256 hash;
  std::vector<char> buf(1 << 16);
  for (;;) {
    const ssize_t n = ::read(in, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(in);
      fail_errno(file, "read: ", err);
    }
    if (n == 0) break;
    hash.update(std::string_view(buf.data(), static_cast<std::size_t>(n)));
  }
  ::close(in);
  return hash.hex();
}

void copy_plain(const fs::path& source, const fs::path& dest) {
  struct stat st {};
  if (::lstat(source.c_str(), &st) != 0) fail_errno(source, "", errno);
  if (!copy_hashing(source, dest, st.st_mode & 07777)) fail_errno(source, "", ENOENT);
}

void fsync_dir(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail_errno(dir, "", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) fail_errno(dir, "fsync: ", err);
}

}  // namespace salient::server::backup_io
