#include "server/api/api_key.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
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
  const bool ok =
      ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw StoreError(path.string() + ": cannot write the API key");
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  store.db()
      .prepare("INSERT INTO api_keys (key_digest, label, created_at) VALUES (?, 'first start', ?)")
      .bind(1, std::string_view(sha256_hex(key)))
      .bind(2, now)
      .run();
  return {key, true};
}

ApiKeys::ApiKeys(Store& store) {
  auto q = store.db().prepare("SELECT key_digest FROM api_keys");
  while (q.step()) digests_.push_back(q.text(0));
}

bool ApiKeys::valid(const HttpRequest& request) const {
  std::string key = request.header("x-api-key");
  const std::string auth = request.header("authorization");
  if (key.empty() && auth.rfind("Bearer ", 0) == 0) key = auth.substr(7);
  if (key.empty()) {
    if (const auto it = request.query.find("apikey"); it != request.query.end()) key = it->second;
  }
  return valid_key(key);
}

bool ApiKeys::valid_key(std::string_view key) const {
  if (key.empty() || key.size() > 256) return false;
  const std::string digest = sha256_hex(key);
  return std::find(digests_.begin(), digests_.end(), digest) != digests_.end();
}

}  // namespace salient::server
