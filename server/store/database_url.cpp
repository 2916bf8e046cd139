#include "server/store/database_url.hpp"

#include "server/store/file_store.hpp"  // StoreError

namespace salient::server {

DatabaseUrl DatabaseUrl::parse(std::string_view text) {
  if (text.empty()) throw StoreError("an empty database URL");
  for (std::string_view scheme : {"postgresql://", "postgres://"})
    if (text.substr(0, scheme.size()) == scheme) return {Dialect::postgresql, std::string(text)};
  if (text.substr(0, 7) == "sqlite:") {
    std::string_view path = text.substr(7);
    if (path.substr(0, 2) == "//") path.remove_prefix(2);  // sqlite:///abs/path as well as sqlite:PATH
    if (path.empty()) throw StoreError("a database URL 'sqlite:' without a path");
    return {Dialect::sqlite, std::string(path)};
  }
  const std::size_t scheme = text.find("://");
  if (scheme != std::string_view::npos)
    throw StoreError("unknown database URL scheme '" + std::string(text.substr(0, scheme)) +
                     "': use a path, sqlite:PATH or postgresql://…");
  return {Dialect::sqlite, std::string(text)};
}

std::string DatabaseUrl::redacted() const {
  if (dialect == Dialect::sqlite) return "sqlite:" + target;
  const std::size_t start = target.find("://") + 3, at = target.find('@', start);
  const std::size_t colon = target.find(':', start);
  if (at == std::string::npos || colon == std::string::npos || colon > at) return target;
  return target.substr(0, colon + 1) + "***" + target.substr(at);
}

}  // namespace salient::server
