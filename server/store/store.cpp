#include "server/store/store.hpp"

#include <memory>
#include <vector>

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
  // One connection per thread and Store, keyed by the Store and not its URL: a Store made later on
  // the same path (a test's next daemon) must not reuse a connection to a database file since
  // deleted (it did, and saw the old rows). A dead Store's connections close
  // at the thread's next call, or when the thread ends.
  struct Connection {
    const void* store;
    std::weak_ptr<const char> alive;
    std::unique_ptr<Database> db;
  };
  thread_local std::vector<Connection> connections;
  std::erase_if(connections, [](const Connection& c) { return c.alive.expired(); });
  for (Connection& c : connections)
    if (c.store == alive_.get()) return *c.db;
  auto db = std::make_unique<Database>(url_);
  return *connections.emplace_back(Connection{alive_.get(), alive_, std::move(db)}).db;
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
