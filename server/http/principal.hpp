// Principal: who made a request, as the router found it from the API key: a user and the role
// that user holds. Roles are ordered: each can do what the ones below it can.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace salient::server {

// viewer: reads only; operator: prints, controls printers, submits jobs; admin: also manages keys.
enum class Role { viewer = 1, operator_ = 2, admin = 3 };

inline std::string_view to_string(Role role) {
  switch (role) {
    case Role::viewer:
      return "viewer";
    case Role::operator_:
      return "operator";
    case Role::admin:
      return "admin";
  }
  return "viewer";
}

// The role of that name; nothing for any other text (an unknown role is refused, never guessed).
inline std::optional<Role> role_from(std::string_view name) {
  if (name == "viewer") return Role::viewer;
  if (name == "operator") return Role::operator_;
  if (name == "admin") return Role::admin;
  return std::nullopt;
}

struct Principal {
  std::string user;
  Role role = Role::viewer;
  long long key_id = 0;  // the key it came with (0: none, e.g. a test's)
};

}  // namespace salient::server
