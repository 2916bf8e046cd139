// UserStore: the users (name, role) and their API keys (tables users and api_keys), of which the
// database holds only SHA-256 digests. Roles are plain names here ("admin", "operator",
// "viewer"); what they allow is the router's business.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/store/database.hpp"

namespace salient::server {

struct UserRow {
  std::string name, role;
  double created_at = 0;
};

struct KeyRow {
  long long id = 0;
  std::string digest;  // SHA-256 of the key, hex
  std::string user, role, label;
  double created_at = 0;
};

class UserStore {
 public:
  explicit UserStore(Database& db) : db_(db) {}

  std::vector<UserRow> users();
  std::optional<UserRow> user(const std::string& name);
  void add_user(const std::string& name, const std::string& role, double now);
  // Every key with its user's role, oldest first.
  std::vector<KeyRow> keys();
  std::optional<KeyRow> key(long long id);
  long long add_key(const std::string& digest, const std::string& user, const std::string& label, double now);
  bool remove_key(long long id);
  // Keys held by admins: the last one is never revoked, so that someone can always manage keys.
  long long admin_keys();

 private:
  Database& db_;
};

}  // namespace salient::server
