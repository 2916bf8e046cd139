#include "server/store/backup.hpp"

#include <unistd.h>

#include <chrono>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>

#include "server/build_info.hpp"
#include "server/store/backup_io.hpp"
#include "server/store/file_store.hpp"  // StoreError

namespace salient::server {
namespace {

namespace fs = std::filesystem;
using namespace backup_io;

// A sweep can take a file only after the row naming it is gone, so each new snapshot misses
// what the last one's rows lost; a handful of rounds is plenty unless the store is damaged.
constexpr int kSnapshots = 5;

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return stamp;
}

void write_manifest(const fs::path& dir, const BackupSummary& s) {
  const nlohmann::json m = {{"format", "salientd-backup"},
                            {"format_version", 1},
                            {"salientd", std::string(version())},
                            {"schema_version", s.schema_version},
                            {"created_at", utc_now()},
                            {"files", s.files},
                            {"bytes", s.bytes}};
  const fs::path p = dir / manifest_name;
  {
    std::ofstream out(p, std::ios::binary);
    out << m.dump(2) << '\n';
    out.flush();
    if (!out) throw StoreError(p.string() + ": cannot write (is the disk full?)", true);
  }
  const fs::path tmp = dir / "manifest.check";
  copy_plain(p, tmp);  // fsyncs a copy; the rename below puts the synced one in place
  fs::rename(tmp, p);
}

// Snapshot, copy what it names, and again while a sweep has taken some of it in between.
BackupSummary copy_consistent(const fs::path& data_dir, const fs::path& stage, const AfterSnapshot& hook,
                              std::set<std::string>& refs) {
  BackupSummary s;
  std::set<std::string> copied, missing;
  for (s.snapshots = 1; s.snapshots <= kSnapshots; ++s.snapshots) {
    fs::remove(stage / database_name);
    snapshot_database(data_dir / database_name, stage / database_name);
    if (hook) hook(s.snapshots);
    refs = referenced_digests(stage / database_name);
    missing.clear();
    for (const std::string& d : refs) {
      if (copied.count(d)) continue;
      if (copy_object(object_path(data_dir, d), object_path(stage, d), d))
        copied.insert(d);
      else
        missing.insert(d);
    }
    if (missing.empty()) break;
  }
  if (!missing.empty())
    throw StoreError(data_dir.string() + ": " + std::to_string(missing.size()) +
                     " stored file(s) its database refers to are missing (first " +
                     missing.begin()->substr(0, 12) +
                     "…): the data directory is damaged; no backup was made");
  s.snapshots = std::min(s.snapshots, kSnapshots);
  // Files an earlier snapshot named and the last one does not: not part of this backup.
  for (const std::string& d : copied)
    if (!refs.count(d)) fs::remove(object_path(stage, d));
  for (const std::string& d : refs) s.bytes += fs::file_size(object_path(stage, d));
  s.files = refs.size();
  s.schema_version = schema_version(stage / database_name);
  return s;
}

}  // namespace

BackupSummary backup_data_dir(const fs::path& data_dir, const fs::path& dest, const AfterSnapshot& hook) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(dest, ec)))
    throw StoreError(dest.string() + " already exists: a backup never overwrites; choose a new name");
  if (!fs::is_regular_file(data_dir / database_name, ec))
    throw StoreError(data_dir.string() + " is not a salientd data directory (no " + database_name +
                     " in it)");
  const fs::path target = fs::absolute(dest).lexically_normal();
  const fs::path parent = target.parent_path();
  if (!fs::is_directory(parent, ec)) throw StoreError(parent.string() + ": no such directory");
  // Written under a hidden name beside DEST (same file system: the rename is atomic).
  const fs::path stage =
      parent / ("." + target.filename().string() + ".partial-" + std::to_string(::getpid()));
  if (!fs::create_directory(stage, ec))
    throw StoreError("cannot write in " + parent.string() + ": " + (ec ? ec.message() : "exists"),
                     ec.value() == ENOSPC);
  try {
    std::set<std::string> refs;
    BackupSummary s = copy_consistent(data_dir, stage, hook, refs);
    if (fs::is_regular_file(data_dir / key_name)) copy_plain(data_dir / key_name, stage / key_name);
    write_manifest(stage, s);
    if (fs::is_directory(stage / "files" / "objects"))
      for (const fs::directory_entry& e : fs::directory_iterator(stage / "files" / "objects"))
        fsync_dir(e.path());
    for (const fs::path& d : {stage / "files" / "objects", stage / "files", stage})
      if (fs::is_directory(d)) fsync_dir(d);
    fs::rename(stage, target);
    fsync_dir(parent);
    return s;
  } catch (...) {
    fs::remove_all(stage, ec);
    throw;
  }
}

}  // namespace salient::server
