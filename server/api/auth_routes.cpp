// Who may do what: OctoPrint's login and current user (the key's user, with OctoPrint's
// permission names for its role), our key management (/api/v1/keys), and OctoPrint's
// application-key workflow (/plugin/appkeys/…) through which Cura and phone apps ask for a key
// that a person approves.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <nlohmann/json.hpp>

#include "server/api/api_json.hpp"
#include "server/api/app_key_requests.hpp"
#include "server/api/routes.hpp"
#include "server/api/sessions.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxBody = 4096, kMaxDepth = 8;

// OctoPrint's permission keys (src/octoprint/access/permissions.py) by its default groups:
// "readonly" for a viewer, "users" for an operator, and the dangerous ones for an admin.
json permissions_of(Role role) {
  json p = {"STATUS",           "WEBCAM",         "FILES_LIST",         "FILES_DOWNLOAD", "GCODE_VIEWER",
            "MONITOR_TERMINAL", "TIMELAPSE_LIST", "TIMELAPSE_DOWNLOAD", "SETTINGS_READ"};
  if (role >= Role::operator_)
    for (const char* k : {"CONNECTION", "FILES_UPLOAD", "FILES_DELETE", "FILES_SELECT", "PRINT", "CONTROL",
                          "SLICE", "TIMELAPSE_DELETE", "TIMELAPSE_ADMIN", "PLUGIN_APPKEYS_GRANT"})
      p.push_back(k);
  if (role == Role::admin)
    for (const char* k : {"ADMIN", "SYSTEM", "SETTINGS", "PLUGIN_APPKEYS_ADMIN"}) p.push_back(k);
  return p;
}

json groups_of(Role role) {
  if (role == Role::admin) return {"admins", "users"};
  if (role == Role::operator_) return {"users"};
  return {"readonly"};
}

const Principal& caller_of(const HttpRequest& r) {
  if (!r.caller) throw ApiError(403, "forbidden", "this needs an API key");
  return *r.caller;
}

json key_json(const KeyInfo& k) {
  return {{"id", k.id},
          {"user", k.user},
          {"role", to_string(k.role)},
          {"label", k.label},
          {"created_at", k.created_at}};
}

std::optional<Role> role_field(const json& body) {
  const std::string name = string_field(body, "role", "");
  if (name.empty()) return std::nullopt;
  const auto role = role_from(name);
  if (!role)
    throw ApiError(400, "bad_role", "unknown role '" + name.substr(0, 32) + "': admin, operator or viewer");
  return role;
}

// Unix seconds: app-key requests are shared by a farm's nodes, whose steady clocks differ.
double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// OctoPrint's decision: true, or one of its "valid boolean trues" as text or number.
std::optional<bool> decision_of(const json& body) {
  const auto it = body.find("decision");
  if (it == body.end()) return std::nullopt;
  if (it->is_boolean()) return it->get<bool>();
  if (it->is_number()) return it->get<double>() == 1;
  if (it->is_string()) {
    const std::string s = it->get<std::string>();
    return s == "true" || s == "yes" || s == "y" || s == "1" || s == "on";
  }
  throw ApiError(400, "bad_request", "'decision' must be true or false");
}

// Decides a pending app request: the key goes to the chosen user, else the one the app named,
// else the user "apps"; a new user gets the chosen role, else operator (print and control, no
// key management).
HttpResponse decide(ApiKeys& keys, AppKeyRequests& requests, const HttpRequest& r, const std::string& token,
                    bool octoprint) {
  keys.confirm(caller_of(r));  // an approval mints a key
  const json body = parse_json_body(r, kMaxBody, kMaxDepth);
  const std::optional<bool> approve = decision_of(body);
  if (!approve) throw ApiError(400, "bad_request", "no decision provided: {\"decision\": true|false}");
  const auto pending = requests.pending(token, unix_now());
  if (!pending) throw ApiError(404, "not_found", "no pending key request with that token");
  std::string user = string_field(body, "user", pending->user.empty() ? "apps" : pending->user);
  if (!valid_user_name(user))
    throw ApiError(400, "bad_user", "not a user name: '" + user.substr(0, 64) + "'");
  std::optional<Role> role = role_field(body);
  if (const auto existing = keys.role_of(user)) {
    if (role && *role != *existing)
      throw ApiError(409, "role_mismatch",
                     "the user '" + user + "' is a " + std::string(to_string(*existing)));
    role.reset();
  } else if (!role) {
    role = Role::operator_;
  }
  if (!requests.decide(token, *approve, user, role, unix_now()))
    throw ApiError(404, "not_found", "no pending key request with that token");
  if (octoprint) return HttpResponse::text(204, "");
  return json_response(200, {{"decision", *approve}, {"app", pending->app}, {"user", user}});
}

void add_login_routes(Router& router, Sessions& sessions) {
  // Passive login ({"passive": true}; a password login is not offered: the key says who it is).
  router.add("POST", "/api/login", Access::viewer, [&sessions](const HttpRequest& r, const PathParams&) {
    const Principal& who = caller_of(r);
    return json_response(200, {{"name", who.user},
                               {"session", sessions.open(who.user, who.key_id)},
                               {"active", true},
                               {"admin", who.role == Role::admin},
                               {"user", true},
                               {"groups", groups_of(who.role)},
                               {"permissions", permissions_of(who.role)},
                               {"roles", {to_string(who.role)}},
                               {"apikey", nullptr},
                               {"settings", json::object()},
                               {"_is_external_client", false},
                               {"_login_mechanism", "apikey"}});
  });
  router.add("GET", "/api/currentuser", Access::viewer, [](const HttpRequest& r, const PathParams&) {
    const Principal& who = caller_of(r);
    return json_response(
        200,
        {{"name", who.user}, {"permissions", permissions_of(who.role)}, {"groups", groups_of(who.role)}});
  });
}

void add_key_routes(Router& router, ApiKeys& keys, Sessions& sessions) {
  // Admins see every key and user; anyone else their own keys.
  router.add("GET", "/api/v1/keys", Access::viewer, [&keys](const HttpRequest& r, const PathParams&) {
    const Principal& who = caller_of(r);
    json list = json::array();
    for (const KeyInfo& k : keys.list())
      if (who.role == Role::admin || k.user == who.user) list.push_back(key_json(k));
    return json_response(
        200,
        {{"keys", list}, {"you", {{"user", who.user}, {"role", to_string(who.role)}, {"key", who.key_id}}}});
  });
  router.add("POST", "/api/v1/keys", Access::admin, [&keys](const HttpRequest& r, const PathParams&) {
    keys.confirm(caller_of(r));
    const json body = parse_json_body(r, kMaxBody, kMaxDepth);
    const std::string user = string_field(body, "user", "");
    if (user.empty())
      throw ApiError(400, "bad_request", "name the key's user: {\"user\": NAME, \"role\": ROLE}");
    const NewKey made = keys.create(user, role_field(body), string_field(body, "label", ""));
    json out = key_json(made.info);
    out["key"] = made.key;  // shown this once
    HttpResponse resp = json_response(201, out);
    resp.headers.emplace_back("Location", "/api/v1/keys/" + std::to_string(made.info.id));
    return resp;
  });
  // A user may revoke their own keys (a leaked phone's); admins any but the last admin key.
  router.add("DELETE", "/api/v1/keys/{id}", Access::viewer,
             [&keys, &sessions](const HttpRequest& r, const PathParams& p) {
               const Principal& who = caller_of(r);
               const std::string& text = p.at("id");
               long long id = 0;
               const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), id);
               if (ec != std::errc() || end != text.data() + text.size())
                 throw NotFound("no key " + text.substr(0, 32));
               const auto key = keys.find(id);
               if (!key || (who.role != Role::admin && key->user != who.user))
                 throw NotFound("no key " + text);
               keys.confirm(who);
               const KeyInfo gone = keys.revoke(id);
               if (!keys.has_keys(gone.user)) sessions.close_user(gone.user);
               return json_response(200, {{"revoked", key_json(gone)}});
             });
}

void add_request_routes(Router& router, ApiKeys& keys, AppKeyRequests& requests) {
  router.add("GET", "/api/v1/keys/requests", Access::admin,
             [&requests](const HttpRequest&, const PathParams&) {
               const double now = unix_now();
               json list = json::array();
               for (const AppKeyRequest& q : requests.pending(now))
                 list.push_back({{"token", q.user_token},
                                 {"app", q.app},
                                 {"user", q.user.empty() ? json(nullptr) : json(q.user)},
                                 {"remote", q.remote},
                                 {"age_seconds", now - q.created}});
               return json_response(200, {{"requests", list}});
             });
  router.add("POST", "/api/v1/keys/requests/{token}", Access::admin,
             [&keys, &requests](const HttpRequest& r, const PathParams& p) {
               return decide(keys, requests, r, p.at("token"), false);
             });
  router.add("POST", "/plugin/appkeys/decision/{token}", Access::admin,
             [&keys, &requests](const HttpRequest& r, const PathParams& p) {
               return decide(keys, requests, r, p.at("token"), true);
             });
}

// What an app without a key may call (open; bodies of at most Router's kOpenBodyLimit).
void add_app_routes(Router& router, ApiKeys& keys, AppKeyRequests& requests) {
  router.add("GET", "/plugin/appkeys/probe", Access::open,
             [](const HttpRequest&, const PathParams&) { return HttpResponse::text(204, ""); });
  router.add(
      "POST", "/plugin/appkeys/request", Access::open, [&requests](const HttpRequest& r, const PathParams&) {
        const json body = parse_json_body(r, kMaxBody, kMaxDepth);
        const std::string app = string_field(body, "app", "");
        if (app.empty() || app.size() > 128 || std::any_of(app.begin(), app.end(), [](char c) {
              return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
            }))
          throw ApiError(400, "bad_request", "name the app (1-128 printable characters): {\"app\": NAME}");
        const std::string user =
            body.contains("user") && body["user"].is_null() ? "" : string_field(body, "user", "");
        if (!user.empty() && !valid_user_name(user))
          throw ApiError(400, "bad_user", "not a user name: '" + user.substr(0, 64) + "'");
        const AppKeyRequest made = requests.open(app, user, r.remote, unix_now());
        const std::string poll = "/plugin/appkeys/request/" + made.app_token;
        std::string host = r.header("host");
        const bool plain_host =
            !host.empty() && host.size() <= 255 &&
            host.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-:[]") ==
                std::string::npos;
        // The URL the client used: behind a trusted proxy, its scheme, host and prefix.
        const std::string base = plain_host ? r.scheme + "://" + host + r.base_path : "";
        HttpResponse resp = json_response(
            201, {{"app_token", made.app_token}, {"auth_dialog", (base.empty() ? r.base_path : base) + "/"}});
        resp.headers.emplace_back("Location", base + poll);
        return resp;
      });
  router.add("GET", "/plugin/appkeys/request/{token}", Access::open,
             [&keys, &requests](const HttpRequest&, const PathParams& p) {
               const auto polled = requests.poll(p.at("token"), unix_now());
               if (polled.state == AppKeyRequests::Poll::pending)
                 return json_response(202, {{"message", "Awaiting decision"}});
               if (polled.state == AppKeyRequests::Poll::unknown)
                 throw ApiError(404, "not_found", "no such key request: denied, expired or never made");
               const NewKey made = keys.create(polled.request.key_user, polled.request.key_role,
                                               polled.request.app.substr(0, 128));
               return json_response(200, {{"api_key", made.key}});
             });
}

}  // namespace

void add_auth_routes(Router& router, ApiKeys& keys, Sessions& sessions, AppKeyRequests& requests) {
  add_login_routes(router, sessions);
  add_key_routes(router, keys, sessions);
  add_request_routes(router, keys, requests);
  add_app_routes(router, keys, requests);
}

}  // namespace salient::server
