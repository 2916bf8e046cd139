// API keys, users and roles on a real store: keys of 43 URL-safe characters stored as digests,
// made and revoked at run time and seen at once, the last admin key kept, bad names and roles
// refused, and a hex key of the schema before users (version 3) still an admin's after the
// migration.
#include "server/api/api_key.hpp"

#include <doctest/doctest.h>
#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <thread>

#include "server/api/sessions.hpp"
#include "server/common/domain_error.hpp"
#include "server/store/sha256.hpp"
#include "server/store/user_store.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;

namespace {

bool url_safe_43(const std::string& key) {
  return std::regex_match(key, std::regex("^[A-Za-z0-9_-]{43}$"));
}

HttpRequest with_key(const std::string& header, const std::string& key) {
  HttpRequest r;
  r.headers[header] = key;
  return r;
}

}  // namespace

TEST_CASE("the first start's key: 43 URL-safe characters, mode 0600, the admin's, stored as a digest") {
  salient::test::ScratchDir dir("keys-first");
  Store store(dir.path);
  const ApiKey first = ensure_api_key(store);
  REQUIRE(first.created);
  CHECK(url_safe_43(first.key));
  std::ifstream file(dir.path / "api-key");
  std::string line;
  std::getline(file, line);
  CHECK(line == first.key);
  struct stat st {};
  REQUIRE(::stat((dir.path / "api-key").c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0600);
  CHECK_FALSE(ensure_api_key(store).created);  // made once

  ApiKeys keys(store);
  const auto who = keys.authenticate(with_key("x-api-key", first.key));
  REQUIRE(who);
  CHECK(who->user == "admin");
  CHECK(who->role == Role::admin);
  CHECK(keys.authenticate(with_key("authorization", "Bearer " + first.key)));
  const auto rows = UserStore(store.db()).keys();
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].digest == sha256_hex(first.key));
  CHECK(rows[0].digest != first.key);
}

TEST_CASE(
    "tokens are URL-safe base64 never starting with a dash so that a command line takes them as arguments") {
  // 1 in 64 raw draws starts with '-': `salient keys approve -x…` failed as "token is required".
  std::set<std::string> seen;
  std::set<char> firsts;
  for (int i = 0; i < 20000; ++i) {
    const std::string t = random_token(32);
    REQUIRE(url_safe_43(t));
    REQUIRE(t.front() != '-');
    seen.insert(t);
    firsts.insert(t.front());
  }
  CHECK(seen.size() == 20000);
  CHECK(firsts.size() == 63);  // every other character still starts one
  CHECK(random_token(24).size() == 32);
  CHECK(random_token(1).size() == 2);
  CHECK(random_token(0).empty());
}

TEST_CASE("keys made and revoked at run time are seen at once, from any thread") {
  salient::test::ScratchDir dir("keys-runtime");
  Store store(dir.path);
  const std::string admin_key = ensure_api_key(store).key;
  ApiKeys keys(store);
  const NewKey viewer = keys.create("vic", Role::viewer, "phone");
  CHECK(url_safe_43(viewer.key));
  CHECK(viewer.info.user == "vic");
  CHECK(viewer.info.role == Role::viewer);
  CHECK(viewer.info.label == "phone");
  std::optional<Principal> seen;
  std::thread([&] { seen = keys.principal(viewer.key); }).join();  // another thread, its own connection
  REQUIRE(seen);
  CHECK(seen->user == "vic");
  CHECK(seen->role == Role::viewer);
  CHECK(seen->key_id == viewer.info.id);
  // A second key for the same user takes the user's role; another role is a conflict.
  const NewKey again = keys.create("vic", std::nullopt, "");
  CHECK(keys.principal(again.key)->role == Role::viewer);
  CHECK(again.key != viewer.key);
  CHECK_THROWS_AS(keys.create("vic", Role::admin, ""), Conflict);
  // A new user without a role is a viewer: least power by default.
  CHECK(keys.principal(keys.create("nora", std::nullopt, "").key)->role == Role::viewer);
  CHECK(keys.has_keys("vic"));

  keys.revoke(viewer.info.id);
  CHECK_FALSE(keys.valid_key(viewer.key));
  CHECK(keys.valid_key(again.key));
  CHECK_THROWS_AS(keys.revoke(viewer.info.id), NotFound);
  keys.revoke(again.info.id);
  CHECK_FALSE(keys.has_keys("vic"));
  CHECK(keys.valid_key(admin_key));
  // A restart reads the same keys.
  ApiKeys reread(store);
  CHECK(reread.valid_key(admin_key));
  CHECK_FALSE(reread.valid_key(again.key));
  CHECK(reread.list().size() == 2);
}

TEST_CASE("the last admin key is never revoked, and another admin key frees it") {
  salient::test::ScratchDir dir("keys-last-admin");
  Store store(dir.path);
  const std::string first = ensure_api_key(store).key;
  ApiKeys keys(store);
  const long long first_id = keys.principal(first)->key_id;
  keys.create("otto", Role::operator_, "");  // an operator's key does not count
  try {
    keys.revoke(first_id);
    FAIL("the last admin key was revoked");
  } catch (const Conflict& e) {
    CHECK(e.code() == "last_admin_key");
  }
  CHECK(keys.valid_key(first));
  const NewKey second = keys.create("ada", Role::admin, "");
  keys.revoke(first_id);
  CHECK_FALSE(keys.valid_key(first));
  CHECK_THROWS_AS(keys.revoke(second.info.id), Conflict);
}

TEST_CASE("bad user names, labels and keys are refused, never crash") {
  salient::test::ScratchDir dir("keys-bad");
  Store store(dir.path);
  ensure_api_key(store);
  ApiKeys keys(store);
  for (const std::string& name :
       {std::string(), std::string("_api"), std::string("a b"), std::string(65, 'a'), std::string("é"),
        std::string("a/b"), std::string("x\n")})
    CHECK_THROWS_AS(keys.create(name, Role::viewer, ""), BadRequest);
  CHECK_THROWS_AS(keys.create("ok", Role::viewer, std::string(129, 'l')), BadRequest);
  CHECK_THROWS_AS(keys.create("ok", Role::viewer, "tab\there"), BadRequest);
  CHECK(valid_user_name("fdm-monster_2.0"));
  for (const std::string& key :
       {std::string(), std::string(100000, 'a'), std::string("\0\0", 2), std::string("' OR 1=1 --")})
    CHECK_FALSE(keys.valid_key(key));
  CHECK(keys.list().size() == 1);
}

TEST_CASE("a hex key of a data directory from before users (schema 3) is the admin's after the migration") {
  salient::test::ScratchDir dir("keys-migration");
  std::filesystem::create_directories(dir.path);
  const std::string hex = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
  {
    // Schema 3 as it shipped: api_keys without a user, no users table.
    Database old(dir.path / "salient.db");
    old.exec(
        "DROP INDEX api_keys_by_user; ALTER TABLE api_keys DROP COLUMN user; DROP TABLE users; "
        "DROP TABLE folders; DROP TABLE settings; "
        "ALTER TABLE prints DROP COLUMN filament_mm; ALTER TABLE prints DROP COLUMN paused_seconds; "
        "DROP INDEX jobs_by_node; ALTER TABLE jobs DROP COLUMN node; "
        "ALTER TABLE jobs DROP COLUMN lease_until; ALTER TABLE jobs DROP COLUMN cancel_requested; "
        "ALTER TABLE jobs DROP COLUMN requeues; "
        "DROP TABLE event_payloads; DROP TABLE sessions; DROP TABLE app_key_requests; DROP TABLE nodes; DROP "
        "TABLE farm_printers; DROP TABLE printer_requests; "
        "PRAGMA user_version = 3;");
    old.prepare("INSERT INTO api_keys (key_digest, label, created_at) VALUES (?, 'first start', 1)")
        .bind(1, std::string_view(sha256_hex(hex)))
        .run();
  }
  Store store(dir.path);  // this thread's first connection to it: migrates 3 -> latest
  CHECK(store.db().schema_version() == Database::latest_schema_version());
  CHECK_FALSE(ensure_api_key(store).created);  // a key exists: no new one
  ApiKeys keys(store);
  const auto who = keys.principal(hex);
  REQUIRE(who);
  CHECK(who->user == "admin");
  CHECK(who->role == Role::admin);
  // And it is the admin key that may not go last.
  CHECK_THROWS_AS(keys.revoke(who->key_id), Conflict);
}

// Issue 32: in a farm each node kept its own copy of the keys, so a key revoked on node A still
// worked on node B (an admin's minted new keys there), and one made on A was refused on B. Two
// ApiKeys on one store are two nodes' caches of one table.
TEST_CASE("a key made or revoked through another node is seen here within a second, with its sessions") {
  salient::test::ScratchDir dir("keys-nodes");
  Store store(dir.path);
  const ApiKey first = ensure_api_key(store);
  ApiKeys a(store);
  Sessions sessions(store);  // node B's, outliving its keys' refresher
  ApiKeys b(store);
  b.on_revoked([&sessions](long long id) { sessions.close_key(id); });
  b.start_refresh(std::chrono::milliseconds(100), {});
  // Within a second, measured: polls every 20 ms.
  const auto within_a_second = [](const std::function<bool()>& seen) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (!seen() && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return seen();
  };

  const NewKey phone = a.create("otto", Role::operator_, "phone");
  const NewKey laptop = a.create("otto", std::nullopt, "laptop");
  const NewKey boss = a.create("boss", Role::admin, "");
  CHECK(within_a_second([&] { return b.valid_key(phone.key) && b.valid_key(boss.key); }));
  const std::string on_phone = sessions.open("otto", phone.info.id);
  const std::string on_laptop = sessions.open("otto", laptop.info.id);

  a.revoke(phone.info.id);
  CHECK(within_a_second([&] { return !b.valid_key(phone.key); }));
  // Its session ends with it, though otto holds another key; the other key's session stays.
  CHECK(within_a_second([&] { return !sessions.user_of(on_phone); }));
  CHECK(sessions.user_of(on_laptop) == std::optional<std::string>("otto"));
  CHECK(b.valid_key(laptop.key));

  // A revoked admin key is refused on B before it can make another key there.
  a.revoke(boss.info.id);
  CHECK(within_a_second([&] { return !b.principal(boss.key); }));
  CHECK(b.valid_key(first.key));
  b.stop_refresh();
}

// Issue 32: sessions lived in the memory of the node that logged the client in, so a push socket
// opened on another node of a farm was told to log in again, forever. Two Sessions on one
// database are two nodes.
TEST_CASE("a session opened on one node authenticates on another, and a revoke there ends it") {
  salient::test::ScratchDir dir("sessions-nodes");
  Store a_store(dir.path), b_store(dir.path);
  Sessions a(a_store), b(b_store);
  const std::string phone = a.open("otto", 7), laptop = a.open("otto", 8), vic = b.open("vic", 9);
  CHECK(b.user_of_auth("otto:" + phone) == std::optional<std::string>("otto"));
  CHECK_FALSE(b.user_of_auth("vic:" + phone));  // the name must be the session's
  CHECK(a.user_of(vic) == std::optional<std::string>("vic"));
  const std::uint64_t closes = b.closes();
  b.close_key(7);
  CHECK(b.closes() == closes + 1);  // what the push hub watches before asking the database again
  CHECK_FALSE(a.user_of(phone));
  CHECK(a.user_of(laptop) == std::optional<std::string>("otto"));
  a.close_user("otto");
  CHECK_FALSE(b.user_of(laptop));
  CHECK(b.user_of(vic) == std::optional<std::string>("vic"));
  // Only digests are kept: a copy of the database opens no push socket.
  auto q = a_store.db().prepare("SELECT session_digest FROM sessions");
  REQUIRE(q.step());
  CHECK(q.text(0) != vic);
  CHECK(q.text(0).size() == 64);
}
