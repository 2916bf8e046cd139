#include "server/store/user_store.hpp"

namespace salient::server {
namespace {

constexpr const char* key_columns =
    "SELECT k.id, k.key_digest, k.\"user\", COALESCE(u.role, 'viewer'), k.label, k.created_at "
    "FROM api_keys k LEFT JOIN users u ON u.name = k.\"user\"";

KeyRow read_key(const Database::Statement& q) {
  return {q.integer(0), q.text(1), q.text(2), q.text(3), q.text(4), q.real(5)};
}

}  // namespace

std::vector<UserRow> UserStore::users() {
  auto q = db_.prepare("SELECT name, role, created_at FROM users ORDER BY name");
  std::vector<UserRow> out;
  while (q.step()) out.push_back({q.text(0), q.text(1), q.real(2)});
  return out;
}

std::optional<UserRow> UserStore::user(const std::string& name) {
  auto q = db_.prepare("SELECT name, role, created_at FROM users WHERE name = ?");
  q.bind(1, std::string_view(name));
  if (!q.step()) return std::nullopt;
  UserRow u{q.text(0), q.text(1), q.real(2)};
  q.run();
  return u;
}

void UserStore::add_user(const std::string& name, const std::string& role, double now) {
  db_.prepare("INSERT INTO users (name, role, created_at) VALUES (?, ?, ?)")
      .bind(1, std::string_view(name))
      .bind(2, std::string_view(role))
      .bind(3, now)
      .run();
}

std::vector<KeyRow> UserStore::keys() {
  auto q = db_.prepare(std::string(key_columns) + " ORDER BY k.id");
  std::vector<KeyRow> out;
  while (q.step()) out.push_back(read_key(q));
  return out;
}

std::optional<KeyRow> UserStore::key(long long id) {
  auto q = db_.prepare(std::string(key_columns) + " WHERE k.id = ?");
  q.bind(1, static_cast<std::int64_t>(id));
  if (!q.step()) return std::nullopt;
  KeyRow k = read_key(q);
  q.run();
  return k;
}

long long UserStore::add_key(const std::string& digest, const std::string& user, const std::string& label,
                             double now) {
  // "user" quoted: a reserved word in PostgreSQL (SQLite takes the quotes too).
  auto q = db_.prepare(
      "INSERT INTO api_keys (key_digest, \"user\", label, created_at) VALUES (?, ?, ?, ?) RETURNING id");
  q.bind(1, std::string_view(digest))
      .bind(2, std::string_view(user))
      .bind(3, std::string_view(label))
      .bind(4, now);
  q.step();
  const long long id = q.integer(0);
  q.run();
  return id;
}

bool UserStore::remove_key(long long id) {
  db_.prepare("DELETE FROM api_keys WHERE id = ?").bind(1, static_cast<std::int64_t>(id)).run();
  return db_.changes() > 0;
}

long long UserStore::admin_keys() {
  auto q = db_.prepare(
      "SELECT COUNT(*) FROM api_keys k JOIN users u ON u.name = k.\"user\" WHERE u.role = 'admin'");
  q.step();
  const long long n = q.integer(0);
  q.run();
  return n;
}

}  // namespace salient::server
