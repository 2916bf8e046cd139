// SettingsStore: small documents clients write and expect back after a restart (table settings),
// by key: OctoPrint's settings that its clients change (POST /api/settings), as JSON text.
#pragma once

#include <optional>
#include <string>

#include "server/store/database.hpp"

namespace salient::server {

class SettingsStore {
 public:
  explicit SettingsStore(Database& db) : db_(db) {}

  std::optional<std::string> get(const std::string& key);
  void put(const std::string& key, const std::string& value, double now);

 private:
  Database& db_;
};

}  // namespace salient::server
