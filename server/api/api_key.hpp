// API keys: each belongs to a user, whose role says what the key may do. A key is 43 URL-safe
// characters (32 random bytes, as OctoPrint makes them and FDM Monster's validator accepts);
// the hex keys of earlier versions keep working. The database keeps only SHA-256 digests: a key
// is shown once, when it is made. The first start makes one for the user 'admin' and writes it
// to DATA/api-key (mode 0600) for the owner to read.
#pragma once

#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "server/http/http_message.hpp"
#include "server/store/store.hpp"

namespace salient::server {

struct ApiKey {
  std::string key;  // only when it was made now (to show once); else empty
  bool created = false;
};

ApiKey ensure_api_key(Store& store);

struct KeyInfo {
  long long id = 0;
  std::string user;
  Role role = Role::viewer;
  std::string label;
  double created_at = 0;  // Unix seconds
};

struct NewKey {
  KeyInfo info;
  std::string key;  // the key itself: shown this once, never stored
};

// A user name: 1–64 characters of [A-Za-z0-9._-], not starting with '_' (OctoPrint's "_api"
// means "no user" to its clients).
bool valid_user_name(std::string_view name);

// The keys in memory (digest → who), so that checking a request touches no database; made and
// revoked at run time, each change written to the database first. Thread-safe.
class ApiKeys {
 public:
  explicit ApiKeys(Store& store);

  // The key from X-Api-Key, Authorization: Bearer, or ?apikey= (as OctoPrint; for browsers'
  // WebSockets, which cannot set headers), and whose it is.
  std::optional<Principal> authenticate(const HttpRequest& request) const;
  std::optional<Principal> principal(std::string_view key) const;
  bool valid(const HttpRequest& request) const { return authenticate(request).has_value(); }
  bool valid_key(std::string_view key) const { return principal(key).has_value(); }

  // A new key for `user`, made with `role` if the user is new (a new user without a role is a
  // viewer). BadRequest for a bad name or label, Conflict when an existing user has another role.
  NewKey create(const std::string& user, std::optional<Role> role, const std::string& label);
  // NotFound for no such key; Conflict for the last key of any admin (nobody locks themselves out).
  KeyInfo revoke(long long id);
  std::vector<KeyInfo> list() const;
  std::optional<KeyInfo> find(long long id) const;
  std::optional<Role> role_of(const std::string& user) const;
  // Whether `user` holds any key still (its sessions end with its last key).
  bool has_keys(const std::string& user) const;

 private:
  void load();
  Store& store_;
  std::mutex write_;  // one change at a time: its check and its write together
  mutable std::shared_mutex mutex_;
  std::unordered_map<std::string, Principal> by_digest_;
};

}  // namespace salient::server
