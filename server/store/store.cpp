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

}  // namespace salient::server
