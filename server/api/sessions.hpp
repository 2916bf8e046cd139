// Sessions: what OctoPrint's passive login hands a client (a random id bound to a user), and what
// its push socket's {"auth": "name:session"} is checked against. In the database (table
// sessions, as SHA-256 digests), so that a farm's nodes share them: a client that logged in
// through one node authenticates its push socket on another. Bounded: the oldest go first.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace salient::server {

class Store;

// `bytes` random bytes from the kernel as URL-safe base64 without padding (Python's
// secrets.token_urlsafe, which OctoPrint uses: 32 bytes make 43 characters), never starting with
// '-' so that a command line takes it as an argument, not an option.
std::string random_token(std::size_t bytes);

// Thread-safe (each thread uses its own connection). Each call throws StoreError when the database
// cannot be reached.
class Sessions {
 public:
  static constexpr std::size_t kMax = 4096;
  explicit Sessions(Store& store) : store_(store) {}
  // A new session for `user` (a user name), opened with key `key_id`, returned to the client.
  std::string open(const std::string& user, long long key_id = 0);
  // The user a "name:session" string (the push socket's auth) or a session belongs to.
  std::optional<std::string> user_of_auth(std::string_view auth) const;
  std::optional<std::string> user_of(std::string_view session) const;
  // Forget every session of `user` (a revoked key, a deleted user).
  void close_user(const std::string& user);
  // Forget the sessions opened with key `key_id` (revoked), though its user may hold another.
  void close_key(long long key_id);
  // How many closes this node has made (each node makes one for every key revoked anywhere):
  // what holds sessions need look again only when it moved, not ask the database every second.
  std::uint64_t closes() const { return closes_.load(); }

 private:
  Store& store_;
  std::atomic<std::uint64_t> closes_{0};
};

}  // namespace salient::server
