// `salient keys list|create|revoke|requests|approve|deny`: salientd's API keys and the apps
// waiting for one, over its REST API (/api/v1/keys…). A new key is printed alone on stdout (it is
// shown this once); what it is goes to stderr. Exit status 0, 1 when the daemon refused (its
// message on stderr), 4 when it could not be reached.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "clients/cli/commands.hpp"
#include "clients/cli/daemon_client.hpp"

namespace salient::cli {
namespace {

using nlohmann::json;

struct KeysOptions {
  std::string server, key;
  bool json = false;
  std::string user, role, label, id, token;
};

void add_daemon_options(CLI::App& cmd, KeysOptions& o) {
  cmd.add_option("--server", o.server, "salientd's URL (default: $SALIENT_SERVER or http://127.0.0.1:8080)");
  cmd.add_option("--key", o.key, "API key (default: $SALIENT_API_KEY or var/api-key)");
  cmd.add_flag("--json", o.json, "Print the daemon's JSON instead of text");
}

// Tokens and ids go into the URL's path: only their own characters, so nothing else slips in.
bool plain(const std::string& s) {
  return s.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") ==
         std::string::npos;
}

int run(const KeysOptions& o, const std::function<int(DaemonClient&)>& f) {
  if (!plain(o.id) || !plain(o.token)) {
    std::fprintf(stderr, "salient: error: not a key id or request token: '%s'\n", (o.id + o.token).c_str());
    return 1;
  }
  try {
    DaemonClient client(resolve_daemon(o.server, o.key));
    return f(client);
  } catch (const DaemonError& e) {
    std::fprintf(stderr, "salient: error: %s\n", e.what());
    return e.status() == 0 ? 4 : 1;
  }
}

int list(DaemonClient& c, const KeysOptions& o) {
  const DaemonReply r = c.request("GET", "/api/v1/keys");
  if (o.json) return std::printf("%s\n", r.body.c_str()), 0;
  const json all = json::parse(r.body);
  for (const json& k : all["keys"])
    std::printf("%-5lld %-16s %-8s %s\n", k.value("id", 0LL), k.value("user", "").c_str(),
                k.value("role", "").c_str(), k.value("label", "").c_str());
  return 0;
}

int create(DaemonClient& c, const KeysOptions& o) {
  json body = {{"user", o.user}};
  if (!o.role.empty()) body["role"] = o.role;
  if (!o.label.empty()) body["label"] = o.label;
  const DaemonReply r = c.request("POST", "/api/v1/keys", body.dump());
  if (o.json) return std::printf("%s\n", r.body.c_str()), 0;
  const json k = json::parse(r.body);
  std::printf("%s\n", k.value("key", "").c_str());
  std::fprintf(stderr, "key %lld for %s (%s): shown this once\n", k.value("id", 0LL),
               k.value("user", "").c_str(), k.value("role", "").c_str());
  return 0;
}

int requests(DaemonClient& c, const KeysOptions& o) {
  const DaemonReply r = c.request("GET", "/api/v1/keys/requests");
  if (o.json) return std::printf("%s\n", r.body.c_str()), 0;
  const json all = json::parse(r.body);
  for (const json& q : all["requests"])
    std::printf("%s  %s  from %s%s  %.0f s ago\n", q.value("token", "").c_str(), q.value("app", "").c_str(),
                q.value("remote", "").c_str(),
                q["user"].is_string() ? (" for " + q["user"].get<std::string>()).c_str() : "",
                q.value("age_seconds", 0.0));
  return 0;
}

int decide(DaemonClient& c, const KeysOptions& o, bool approve) {
  json body = {{"decision", approve}};
  if (!o.user.empty()) body["user"] = o.user;
  if (!o.role.empty()) body["role"] = o.role;
  const DaemonReply r = c.request("POST", "/api/v1/keys/requests/" + o.token, body.dump());
  if (o.json) return std::printf("%s\n", r.body.c_str()), 0;
  const json d = json::parse(r.body);
  if (approve)
    std::printf("approved: %s gets a key for %s at its next poll\n", d.value("app", "").c_str(),
                d.value("user", "").c_str());
  else
    std::printf("denied: %s\n", d.value("app", "").c_str());
  return 0;
}

}  // namespace

void add_keys_command(CLI::App& app, CommandAction& action) {
  CLI::App* keys =
      app.add_subcommand("keys", "salientd's API keys, users and roles, and apps asking for a key");
  keys->require_subcommand(1);
  auto o = std::make_shared<KeysOptions>();
  const auto sub = [&](const char* name, const char* what, std::function<int(DaemonClient&)> f) {
    CLI::App* cmd = keys->add_subcommand(name, what);
    add_daemon_options(*cmd, *o);
    cmd->callback([o, f, &action] { action = [o, f] { return run(*o, f); }; });
    return cmd;
  };
  sub("list", "List the keys (an admin sees all, anyone else their own)",
      [o](DaemonClient& c) { return list(c, *o); });
  CLI::App* make = sub("create", "Make a key for USER (a new user gets --role, default viewer); printed once",
                       [o](DaemonClient& c) { return create(c, *o); });
  make->add_option("user", o->user, "The key's user")->required();
  make->add_option("--role", o->role, "admin, operator or viewer (for a new user)");
  make->add_option("--label", o->label, "What the key is for (e.g. the app)");
  CLI::App* revoke = sub("revoke", "Revoke the key ID (see `salient keys list`)", [o](DaemonClient& c) {
    c.request("DELETE", "/api/v1/keys/" + o->id);
    std::printf("revoked key %s\n", o->id.c_str());
    return 0;
  });
  revoke->add_option("id", o->id, "The key's id")->required();
  sub("requests", "List the apps waiting for a key (OctoPrint's application keys)",
      [o](DaemonClient& c) { return requests(c, *o); });
  for (const bool approve : {true, false}) {
    CLI::App* cmd = sub(approve ? "approve" : "deny",
                        approve ? "Approve an app's key request: its next poll gets a key"
                                : "Deny an app's key request: its next poll gets 404",
                        [o, approve](DaemonClient& c) { return decide(c, *o, approve); });
    cmd->add_option("token", o->token, "The request's token (see `salient keys requests`)")->required();
    if (approve) {
      cmd->add_option("--user", o->user, "Whose key it is (default: the user the app named, else 'apps')");
      cmd->add_option("--role", o->role, "The role of a new user (default operator)");
    }
  }
}

}  // namespace salient::cli
