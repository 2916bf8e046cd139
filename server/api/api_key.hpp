// API keys: each belongs to a user, whose role says what the key may do. A key is 43 URL-safe
// characters (32 random bytes, as OctoPrint makes them and FDM Monster's validator accepts);
// the hex keys of earlier versions keep working. The database keeps only SHA-256 digests: a key
// is shown once, when it is made. The first start makes one for the user 'admin' and writes it
// to DATA/api-key (mode 0600) for the owner to read.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <string_view>
#include <thread>
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

// What was opened with a key and must end with it (a WebSocket): told once, on the thread that
// found the key gone, when its key is revoked on any node.
struct KeyWatch {
  long long key_id = 0;
  std::function<void()> revoked;
};

// The keys in memory (digest → who), so that checking a request touches no database; made and
// revoked at run time, each change written to the database first. Thread-safe.
// In a farm every node changes the same table: start_refresh reads it again every `every` (a
// key made or revoked on another node counts here within that), so that a revoked key is
// refused by every node, not only by the one that revoked it.
class ApiKeys {
 public:
  explicit ApiKeys(Store& store);
  ~ApiKeys();  // stop_refresh()
  ApiKeys(const ApiKeys&) = delete;
  ApiKeys& operator=(const ApiKeys&) = delete;

  // Reads the keys again; a key gone since tells its watches. Throws StoreError.
  void refresh();
  // A thread that refreshes every `every`; a failed read (the database away) keeps the keys known
  // and is logged once until a read works again.
  void start_refresh(std::chrono::milliseconds every, std::function<void(const std::string&)> log);
  void stop_refresh();
  // Held by the caller: the watch lives as long as its shared_ptr.
  void watch(const std::shared_ptr<KeyWatch>& w);
  // Told of every key gone (its id), on this node or another; set before start_refresh.
  void on_revoked(std::function<void(long long key_id)> f) { on_revoked_ = std::move(f); }

  // The key from X-Api-Key, Authorization: Bearer, or ?apikey= (as OctoPrint; for browsers'
  // WebSockets, which cannot set headers), and whose it is.
  std::optional<Principal> authenticate(const HttpRequest& request) const;
  std::optional<Principal> principal(std::string_view key) const;
  bool valid(const HttpRequest& request) const { return authenticate(request).has_value(); }
  bool valid_key(std::string_view key) const { return principal(key).has_value(); }

  // Throws ApiError 401 unless `who`'s key is still in the database (not only in this node's
  // memory, which may be up to a refresh behind a revocation on another node): asked before what
  // makes or removes keys, so a key revoked anywhere makes none.
  void confirm(const Principal& who) const;
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
  std::mutex load_;   // one read at a time: a slow read must not put back what a later one removed
  mutable std::shared_mutex mutex_;
  std::unordered_map<std::string, Principal> by_digest_;
  std::mutex watches_mutex_;
  std::vector<std::weak_ptr<KeyWatch>> watches_;
  std::function<void(long long)> on_revoked_;
  std::mutex refresh_mutex_;
  std::condition_variable refresh_wake_;
  bool refresh_stop_ = false;
  std::thread refresher_;
};

}  // namespace salient::server
