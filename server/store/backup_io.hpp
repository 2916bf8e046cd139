// The pieces backup and restore share: a consistent copy of a live SQLite database (the online
// backup API), what it refers to in the file store, and copies of stored files that check their
// content address on the way. Internal to server/store; no SQLite type appears here.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <string_view>

namespace salient::server::backup_io {

namespace fs = std::filesystem;

inline constexpr const char* database_name = "salient.db";
inline constexpr const char* manifest_name = "salient-backup.json";
inline constexpr const char* key_name = "api-key";

// One read transaction over `source` (a daemon may be writing it: WAL readers do not block the
// writer) copied page by page into `dest`, a new file. Throws StoreError (disk_full on ENOSPC).
void snapshot_database(const fs::path& source, const fs::path& dest);
// The digests a database's rows name: jobs' models and artefacts, prints' files, uploads.
std::set<std::string> referenced_digests(const fs::path& db);
// "ok", or what PRAGMA integrity_check found; throws StoreError when it is not a database.
std::string integrity_check(const fs::path& db);
int schema_version(const fs::path& db);

// DATA/files/objects/ab/cdef…: where a data directory (or a backup) keeps a digest's bytes.
fs::path object_path(const fs::path& root, std::string_view digest);
// Copies a stored file to `dest` (directories made, fsynced), checking that its bytes hash to
// `digest`; false when the source does not exist (a sweep took it). Throws StoreError otherwise.
bool copy_object(const fs::path& source, const fs::path& dest, std::string_view digest);
std::string file_sha256(const fs::path& file);                  // throws StoreError when it cannot be read
void copy_plain(const fs::path& source, const fs::path& dest);  // fsynced; keeps the mode
void fsync_dir(const fs::path& dir);

}  // namespace salient::server::backup_io
