// Backups of a data directory (`salientd backup DEST`, `salientd restore SRC`).
//
// A backup is a directory: salient.db (an SQLite online-backup snapshot), files/objects/… (the
// stored files the snapshot's rows refer to, nothing else), api-key, and salient-backup.json (a
// manifest that marks it as a backup). It is taken beside a running daemon, from another
// process, without stopping or locking it:
//  1. the database is snapshotted first, in one read transaction (consistent with concurrent
//     writers in WAL mode);
//  2. then the files its rows refer to are copied. Stored files are content-addressed and never
//     change, so a file present is the right one (each copy is hashed to be sure). The daemon's
//     sweep (Store::remove_unreferenced) may delete a file between 1 and 2, once the row that
//     referred to it is gone; then the snapshot is taken again (that row is no longer in it)
//     and the missing files looked for again, a few times. Files already copied stay.
// Retrying was chosen over a lock shared with the daemon: the daemon's sweep holds the mutex
// that uploads wait for, so a lock held for a whole backup would stall uploads for its length.
// The backup is written under a hidden name beside DEST and renamed to DEST at the end: a
// failure (a full disk, a damaged data directory) leaves nothing behind.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace salient::server {

struct BackupSummary {
  int schema_version = 0;
  std::size_t files = 0;     // stored files in it
  std::uintmax_t bytes = 0;  // their sizes together
  int snapshots = 0;         // database snapshots taken (more than one: a sweep raced it)
};

// Test seam: called after each snapshot, before the files are copied.
using AfterSnapshot = std::function<void(int snapshot)>;

// Throws StoreError: DEST exists, DATA is no data directory, a write failed (disk_full()).
BackupSummary backup_data_dir(const std::filesystem::path& data_dir, const std::filesystem::path& dest,
                              const AfterSnapshot& after_snapshot = {});
// Checks a backup whole: the manifest, PRAGMA integrity_check, a schema this salientd can
// migrate, every referenced file present with the right SHA-256. Throws StoreError saying what.
BackupSummary verify_backup(const std::filesystem::path& src);
// Verifies SRC, then installs it into DATA: refused while a daemon holds DATA, or when DATA is
// not empty unless `force` (its contents are then replaced). Nothing is changed on a failure.
BackupSummary restore_data_dir(const std::filesystem::path& src, const std::filesystem::path& data_dir,
                               bool force);

}  // namespace salient::server
