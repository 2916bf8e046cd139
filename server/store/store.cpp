#include "server/store/store.hpp"

#include <map>
#include <memory>

#include "server/store/database_blobs.hpp"

namespace salient::server {
namespace {

std::unique_ptr<RemoteFiles> remote_files(Store& store, const DatabaseUrl& url,
                                          const std::filesystem::path& shared_files) {
  if (url.dialect == Dialect::sqlite || !shared_files.empty()) return nullptr;
  return std::make_unique<DatabaseBlobs>([&store]() -> Database& { return store.db(); });
}

}  // namespace

Store::Store(const std::filesystem::path& data_dir, std::optional<DatabaseUrl> url,
             const std::filesystem::path& shared_files)
    : dir_(data_dir),
      url_(url ? *url : DatabaseUrl::sqlite(data_dir / "salient.db")),
      files_(shared_files.empty() ? data_dir / "files" : shared_files,
             remote_files(*this, url_, shared_files)) {
  db();  // open and migrate now, so that a bad database stops the start
}

Database& Store::db() {
  thread_local std::map<std::string, std::unique_ptr<Database>> connections;
  auto& c = connections[url_.target];
  if (!c) c = std::make_unique<Database>(url_);
  return *c;
}

std::size_t Store::remove_unreferenced(const std::vector<std::string>& digests) {
  std::lock_guard lock(files_mutex_);
  std::size_t removed = 0;
  for (const std::string& d : digests) {
    if (!FileStore::valid_digest(d) || !files_.contains(d)) continue;
    // A job's result names its artefacts by digest inside its JSON: a digest is 64 hex digits,
    // so a substring match cannot hit anything else (and has no LIKE wildcard in it).
    auto q = db().prepare(
        "SELECT (SELECT COUNT(*) FROM jobs WHERE model_digest = ?1 OR result LIKE '%' || ?1 || '%') + "
        "(SELECT COUNT(*) FROM prints WHERE file_digest = ?1) + (SELECT COUNT(*) FROM files WHERE digest = "
        "?1)");
    q.bind(1, std::string_view(d));
    if (q.step() && q.integer(0) > 0) continue;
    files_.remove(d);
    ++removed;
  }
  return removed;
}

}  // namespace salient::server
