#include "server/api/sessions.hpp"

#include <algorithm>
#include <random>

namespace salient::server {

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
  std::lock_guard lock(mutex_);
  if (entries_.size() >= kMax) entries_.pop_front();
  entries_.push_back({session, user, key_id});
  return session;
}

std::optional<std::string> Sessions::user_of(std::string_view session) const {
  std::lock_guard lock(mutex_);
  for (const Entry& e : entries_)
    if (e.session == session) return e.user;
  return std::nullopt;
}

std::optional<std::string> Sessions::user_of_auth(std::string_view auth) const {
  const std::size_t colon = auth.rfind(':');
  if (colon == std::string_view::npos) return std::nullopt;
  const std::optional<std::string> user = user_of(auth.substr(colon + 1));
  if (!user || *user != auth.substr(0, colon)) return std::nullopt;
  return user;
}

void Sessions::close_user(const std::string& user) {
  std::lock_guard lock(mutex_);
  std::erase_if(entries_, [&](const Entry& e) { return e.user == user; });
}

void Sessions::close_key(long long key_id) {
  std::lock_guard lock(mutex_);
  std::erase_if(entries_, [&](const Entry& e) { return e.key_id == key_id; });
}

}  // namespace salient::server
