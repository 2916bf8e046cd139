// salientd restore: verify a backup whole, then install it into a data directory.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "server/store/backup.hpp"
#include "server/store/backup_io.hpp"
#include "server/store/data_dir_lock.hpp"
#include "server/store/database.hpp"

namespace salient::server {
namespace {

namespace fs = std::filesystem;
using namespace backup_io;

void check_manifest(const fs::path& src) {
  std::error_code ec;
  if (!fs::is_directory(src, ec))
    throw StoreError(src.string() + " is not a salientd backup (not a directory)");
  std::ifstream in(src / manifest_name, std::ios::binary);
  if (!in) throw StoreError(src.string() + " is not a salientd backup (no " + manifest_name + " in it)");
  const nlohmann::json m = nlohmann::json::parse(in, nullptr, false);
  if (m.is_discarded() || !m.is_object() || m.value("format", "") != "salientd-backup")
    throw StoreError((src / manifest_name).string() + " is not a salientd backup manifest");
  if (!m.contains("format_version") || !m["format_version"].is_number_integer() || m["format_version"] != 1)
    throw StoreError((src / manifest_name).string() +
                     ": unknown backup format version (made by a newer salientd?)");
}

// Moves each entry of `from` into `to` (same file system) and removes `from`.
void move_entries(const fs::path& from, const fs::path& to) {
  for (const fs::directory_entry& e : fs::directory_iterator(from))
    fs::rename(e.path(), to / e.path().filename());
  fs::remove(from);
}

// Run as root (sudo salientd restore …), the restored files get the data directory's owner, so
// that the daemon's own user (salient) can write them; otherwise they are this user's already.
void give_to_owner(const fs::path& data_dir, const fs::path& tree) {
  struct stat st {};
  if (::geteuid() != 0 || ::stat(data_dir.c_str(), &st) != 0 || st.st_uid == 0) return;
  const auto own = [&](const fs::path& p) {
    if (::lchown(p.c_str(), st.st_uid, st.st_gid) != 0)
      throw StoreError(p.string() + ": chown: " + std::strerror(errno));
  };
  own(tree);
  own(data_dir / DataDirLock::file_name);
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(tree)) own(e.path());
}

// Entries of the data directory other than its lock and our staging directory.
std::vector<fs::path> contents(const fs::path& data_dir, const fs::path& stage) {
  std::vector<fs::path> out;
  for (const fs::directory_entry& e : fs::directory_iterator(data_dir))
    if (e.path().filename() != DataDirLock::file_name && e.path() != stage) out.push_back(e.path());
  return out;
}

// A backup holds plain files and directories only. A link would make the restore (run as root)
// copy whatever it points at, /etc/shadow say, into the data directory for the daemon's user.
void check_plain_tree(const fs::path& src) {
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(src)) {
    const fs::file_status st = e.symlink_status();
    if (fs::is_symlink(st))
      throw StoreError(e.path().string() + " is a symbolic link: a backup holds only plain files, refused");
    if (!fs::is_regular_file(st) && !fs::is_directory(st))
      throw StoreError(e.path().string() +
                       " is not a regular file: a backup holds only plain files, refused");
  }
}

}  // namespace

BackupSummary verify_backup(const fs::path& src) {
  std::error_code ec;
  if (!fs::is_directory(src, ec))
    throw StoreError(src.string() + " is not a salientd backup (not a directory)");
  check_plain_tree(src);  // before anything in it is read
  check_manifest(src);
  const fs::path db = src / database_name;
  if (!fs::is_regular_file(db, ec)) throw StoreError(src.string() + ": the backup has no " + database_name);
  std::string check;
  try {
    check = integrity_check(db);
  } catch (const StoreError& e) {
    throw StoreError(db.string() + ": damaged: " + e.what());
  }
  if (check != "ok")
    throw StoreError(db.string() + ": damaged: integrity_check says " + check.substr(0, 300));
  BackupSummary s;
  s.schema_version = schema_version(db);
  if (s.schema_version > Database::latest_schema_version())
    throw StoreError(src.string() + ": the backup's schema version " + std::to_string(s.schema_version) +
                     " is newer than this salientd's (" + std::to_string(Database::latest_schema_version()) +
                     "): restore it with a newer salientd");
  for (const std::string& d : referenced_digests(db)) {
    const fs::path f = object_path(src, d);
    if (!fs::is_regular_file(f, ec))
      throw StoreError(src.string() + ": damaged: the stored file " + d.substr(0, 12) + "… is missing");
    if (file_sha256(f) != d)
      throw StoreError(src.string() + ": damaged: the stored file " + d.substr(0, 12) + "… has other bytes");
    s.bytes += fs::file_size(f);
    ++s.files;
  }
  return s;
}

BackupSummary restore_data_dir(const fs::path& src, const fs::path& data_dir, bool force) {
  const BackupSummary s = verify_backup(src);
  const DataDirLock lock(data_dir);  // refused while a daemon runs on it; none can start meanwhile
  const fs::path stage = data_dir / (".restore-" + std::to_string(::getpid()));
  const std::vector<fs::path> before = contents(data_dir, stage);
  if (!before.empty() && !force)
    throw StoreError(data_dir.string() + " is not empty (" + before.front().filename().string() +
                     (before.size() > 1 ? " and " + std::to_string(before.size() - 1) + " more" : "") +
                     "): restore into a new directory, or pass --force to replace what is in it");
  std::error_code ec;
  fs::remove_all(stage, ec);
  try {
    fs::create_directory(stage);
    copy_plain(src / database_name, stage / database_name);
    for (const std::string& d : referenced_digests(stage / database_name))
      if (!copy_object(object_path(src, d), object_path(stage, d), d))
        throw StoreError(src.string() + ": the stored file " + d.substr(0, 12) +
                         "… vanished during the restore");
    if (fs::is_regular_file(src / key_name)) copy_plain(src / key_name, stage / key_name);
    fs::create_directories(stage / "files" / "objects");
    for (const fs::directory_entry& e : fs::directory_iterator(stage / "files" / "objects"))
      fsync_dir(e.path());
    fsync_dir(stage / "files" / "objects");
    fsync_dir(stage / "files");
    fsync_dir(stage);
    give_to_owner(data_dir, stage);
  } catch (...) {
    fs::remove_all(stage, ec);
    throw;
  }
  // Everything is staged and synced: only renames from here.
  for (const fs::path& p : before) fs::remove_all(p);
  move_entries(stage, data_dir);
  fsync_dir(data_dir);
  return s;
}

}  // namespace salient::server
