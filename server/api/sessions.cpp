#include "server/api/sessions.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <random>

#include "server/store/sha256.hpp"
#include "server/store/store.hpp"

namespace salient::server {
namespace {

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

std::string random_token(std::size_t bytes) {
  static constexpr char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
  std::random_device rd;  // the kernel's entropy pool
  const auto draw = [&] {
    std::string raw(bytes, '\0');
    for (char& c : raw) c = static_cast<char>(rd() & 0xff);
    std::string out;
    for (std::size_t i = 0; i < bytes; i += 3) {  // base64: 3 bytes -> 4 characters, no padding
      const std::size_t n = std::min<std::size_t>(3, bytes - i);
      unsigned v = 0;
      for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(raw[i + k]) : 0u);
      for (std::size_t k = 0; k < n + 1; ++k) out += alphabet[(v >> (18 - 6 * k)) & 63];
    }
    return out;
  };
  // One draw in 64 starts with '-', which a command line takes for an option (`salient keys
  // approve -x…` failed with "token is required"): such a draw is thrown away (0.02 bits lost).
  std::string token = draw();
  while (!token.empty() && token.front() == '-') token = draw();
  return token;
}

std::string Sessions::open(const std::string& user, long long key_id) {
  std::string session = random_token(24);
  Database& db = store_.db();
  Database::Transaction t(db);
  db.prepare("INSERT INTO sessions (session_digest, user_name, key_id, created_at) VALUES (?, ?, ?, ?)")
      .bind(1, std::string_view(sha256_hex(session)))
      .bind(2, std::string_view(user))
      .bind(3, static_cast<std::int64_t>(key_id))
      .bind(4, unix_now())
      .run();
  auto count = db.prepare("SELECT COUNT(*) FROM sessions");
  count.step();
  const std::int64_t over = count.integer(0) - static_cast<std::int64_t>(kMax);
  count.run();
  if (over > 0)
    db.prepare(
          "DELETE FROM sessions WHERE session_digest IN "
          "(SELECT session_digest FROM sessions ORDER BY created_at, session_digest LIMIT ?)")
        .bind(1, over)
        .run();
  t.commit();
  return session;
}

std::optional<std::string> Sessions::user_of(std::string_view session) const {
  auto q = store_.db().prepare("SELECT user_name FROM sessions WHERE session_digest = ?");
  q.bind(1, std::string_view(sha256_hex(session)));
  if (!q.step()) return std::nullopt;
  std::string user = q.text(0);
  q.run();
  return user;
}

std::optional<std::string> Sessions::user_of_auth(std::string_view auth) const {
  const std::size_t colon = auth.rfind(':');
  if (colon == std::string_view::npos) return std::nullopt;
  const std::optional<std::string> user = user_of(auth.substr(colon + 1));
  if (!user || *user != auth.substr(0, colon)) return std::nullopt;
  return user;
}

void Sessions::close_user(const std::string& user) {
  store_.db().prepare("DELETE FROM sessions WHERE user_name = ?").bind(1, std::string_view(user)).run();
  ++closes_;
}

void Sessions::close_key(long long key_id) {
  store_.db()
      .prepare("DELETE FROM sessions WHERE key_id = ?")
      .bind(1, static_cast<std::int64_t>(key_id))
      .run();
  ++closes_;
}

}  // namespace salient::server
