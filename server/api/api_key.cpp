#include "server/api/api_key.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <random>

#include "server/store/sha256.hpp"

namespace salient::server {

ApiKey ensure_api_key(Store& store) {
  auto q = store.db().prepare("SELECT count(*) FROM api_keys");
  q.step();
  const bool have = q.integer(0) > 0;
  q.run();
  if (have) return {};
  std::random_device rd;  // the kernel's entropy pool
  static constexpr char digits[] = "0123456789abcdef";
  std::string key;
  for (int i = 0; i < 32; ++i) {
    const unsigned b = rd() & 0xff;
    key += digits[b >> 4], key += digits[b & 15];
  }
  const auto path = store.data_dir() / "api-key";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) throw StoreError(path.string() + ": cannot write the API key");
  const std::string line = key + "\n";
  const bool ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw StoreError(path.string() + ": cannot write the API key");
  const double now = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  store.db()
      .prepare("INSERT INTO api_keys (key_digest, label, created_at) VALUES (?, 'first start', ?)")
      .bind(1, std::string_view(sha256_hex(key)))
      .bind(2, now)
      .run();
  return {key, true};
}

bool request_has_valid_key(Store& store, const HttpRequest& request) {
  std::string key = request.header("x-api-key");
  const std::string auth = request.header("authorization");
  if (key.empty() && auth.rfind("Bearer ", 0) == 0) key = auth.substr(7);
  if (key.empty() || key.size() > 256) return false;
  auto q = store.db().prepare("SELECT 1 FROM api_keys WHERE key_digest = ?");
  q.bind(1, std::string_view(sha256_hex(key)));
  const bool found = q.step();
  if (found) q.run();
  return found;
}

}  // namespace salient::server
