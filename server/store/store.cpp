#include "server/store/store.hpp"

#include <map>
#include <memory>

namespace salient::server {

Store::Store(const std::filesystem::path& data_dir)
    : dir_(data_dir), db_path_(data_dir / "salient.db"), files_(data_dir / "files") {
  db();  // open and migrate now, so that a bad database stops the start
}

Database& Store::db() {
  thread_local std::map<std::string, std::unique_ptr<Database>> connections;
  auto& c = connections[db_path_.string()];
  if (!c) c = std::make_unique<Database>(db_path_);
  return *c;
}

std::size_t Store::remove_unreferenced(const std::vector<std::string>& digests) {
  std::lock_guard lock(files_mutex_);
  std::size_t removed = 0;
  for (const std::string& d : digests) {
    if (!FileStore::valid_digest(d) || !files_.contains(d)) continue;
    // A job's result names its artefacts by digest inside its JSON: a digest is 64 hex digits,
    // so a substring match cannot hit anything else.
    auto q = db().prepare(
        "SELECT (SELECT COUNT(*) FROM jobs WHERE model_digest = ?1 OR instr(result, ?1) > 0) + "
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
