// Sessions: what OctoPrint's passive login hands a client (a random id bound to a user), and what
// its push socket's {"auth": "name:session"} is checked against. In memory, as OctoPrint keeps
// them: a restart logs clients out and they log in again. Bounded: the oldest go first.
#pragma once

#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace salient::server {

// `bytes` random bytes from the kernel as URL-safe base64 without padding (Python's
// secrets.token_urlsafe, which OctoPrint uses: 32 bytes make 43 characters), never starting with
// '-' so that a command line takes it as an argument, not an option.
std::string random_token(std::size_t bytes);

class Sessions {
 public:
  static constexpr std::size_t kMax = 4096;
  // A new session for `user` (a user name), opened with key `key_id`, returned to the client.
  std::string open(const std::string& user, long long key_id = 0);
  // The user a "name:session" string (the push socket's auth) or a session belongs to.
  std::optional<std::string> user_of_auth(std::string_view auth) const;
  std::optional<std::string> user_of(std::string_view session) const;
  // Forget every session of `user` (a revoked key, a deleted user).
  void close_user(const std::string& user);
  // Forget the sessions opened with key `key_id` (revoked), though its user may hold another.
  void close_key(long long key_id);

 private:
  struct Entry {
    std::string session, user;
    long long key_id = 0;
  };
  mutable std::mutex mutex_;
  std::deque<Entry> entries_;
};

}  // namespace salient::server
