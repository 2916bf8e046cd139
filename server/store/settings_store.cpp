#include "server/store/settings_store.hpp"

namespace salient::server {

std::optional<std::string> SettingsStore::get(const std::string& key) {
  auto q = db_.prepare("SELECT value FROM settings WHERE key = ?");
  q.bind(1, std::string_view(key));
  if (!q.step()) return std::nullopt;
  std::string value = q.text(0);
  q.run();
  return value;
}

void SettingsStore::put(const std::string& key, const std::string& value, double now) {
  db_.prepare(
         "INSERT INTO settings (key, value, updated_at) VALUES (?, ?, ?) "
         "ON CONFLICT (key) DO UPDATE SET value = excluded.value, updated_at = excluded.updated_at")
      .bind(1, std::string_view(key))
      .bind(2, std::string_view(value))
      .bind(3, now)
      .run();
}

}  // namespace salient::server
