#include "server/api/api_key.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <unordered_set>

#include "server/api/sessions.hpp"
#include "server/common/domain_error.hpp"
#include "server/http/router.hpp"
#include "server/store/sha256.hpp"
#include "server/store/user_store.hpp"

namespace salient::server {
namespace {

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// A key longer than any we make is no key: its digest is never computed.
constexpr std::size_t kMaxKey = 256;

KeyInfo info_of(const KeyRow& row) {
  return {row.id, row.user, role_from(row.role).value_or(Role::viewer), row.label, row.created_at};
}

void write_key_file(const std::filesystem::path& path, const std::string& key) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) throw StoreError(path.string() + ": cannot write the API key");
  const std::string line = key + "\n";
  const bool ok =
      ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw StoreError(path.string() + ": cannot write the API key");
}

}  // namespace

bool valid_user_name(std::string_view name) {
  if (name.empty() || name.size() > 64 || name.front() == '_') return false;
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') return false;
  return true;
}

ApiKey ensure_api_key(Store& store) {
  auto q = store.db().prepare("SELECT count(*) FROM api_keys");
  q.step();
  const bool have = q.integer(0) > 0;
  q.run();
  if (have) return {};
  const std::string key = random_token(32);
  write_key_file(store.data_dir() / "api-key", key);
  UserStore(store.db()).add_key(sha256_hex(key), "admin", "first start", unix_now());
  return {key, true};
}

ApiKeys::ApiKeys(Store& store) : store_(store) {
  load();
}

ApiKeys::~ApiKeys() {
  stop_refresh();
}

void ApiKeys::load() {
  std::lock_guard serial(load_);
  std::unordered_map<std::string, Principal> fresh;
  std::unordered_set<long long> ids;
  for (const KeyRow& row : UserStore(store_.db()).keys()) {
    fresh[row.digest] = {row.user, role_from(row.role).value_or(Role::viewer), row.id};
    ids.insert(row.id);
  }
  std::vector<long long> removed;
  {
    std::unique_lock lock(mutex_);
    for (const auto& [digest, p] : by_digest_)
      if (!ids.count(p.key_id)) removed.push_back(p.key_id);
    by_digest_ = std::move(fresh);
  }
  if (on_revoked_)
    for (const long long id : removed) on_revoked_(id);
  // Told outside the map's lock: a watch may ask about keys.
  std::vector<std::shared_ptr<KeyWatch>> gone;
  {
    std::lock_guard lock(watches_mutex_);
    std::erase_if(watches_, [&](const std::weak_ptr<KeyWatch>& weak) {
      const auto w = weak.lock();
      if (!w) return true;
      if (ids.count(w->key_id)) return false;
      gone.push_back(w);
      return true;
    });
  }
  for (const auto& w : gone)
    if (w->revoked) w->revoked();
}

void ApiKeys::refresh() {
  load();
}

void ApiKeys::watch(const std::shared_ptr<KeyWatch>& w) {
  {
    std::shared_lock lock(mutex_);
    const bool known = std::any_of(by_digest_.begin(), by_digest_.end(),
                                   [&](const auto& entry) { return entry.second.key_id == w->key_id; });
    if (known) {
      std::lock_guard watches(watches_mutex_);
      watches_.push_back(w);
      return;
    }
  }
  if (w->revoked) w->revoked();  // revoked between its check and now
}

void ApiKeys::start_refresh(std::chrono::milliseconds every, std::function<void(const std::string&)> log) {
  stop_refresh();
  refresh_stop_ = false;
  refresher_ = std::thread([this, every, log = std::move(log)] {
    bool failing = false;
    std::unique_lock lock(refresh_mutex_);
    while (!refresh_wake_.wait_for(lock, every, [this] { return refresh_stop_; })) {
      lock.unlock();
      try {
        load();
        if (failing && log) log("keys: read again from the database");
        failing = false;
      } catch (const std::exception& e) {  // the database away: the keys known stay
        if (!failing && log) log(std::string("keys: cannot read them from the database: ") + e.what());
        failing = true;
      }
      lock.lock();
    }
  });
}

void ApiKeys::stop_refresh() {
  {
    std::lock_guard lock(refresh_mutex_);
    refresh_stop_ = true;
  }
  refresh_wake_.notify_all();
  if (refresher_.joinable()) refresher_.join();
}

std::optional<Principal> ApiKeys::authenticate(const HttpRequest& request) const {
  std::string key = request.header("x-api-key");
  const std::string auth = request.header("authorization");
  if (key.empty() && auth.rfind("Bearer ", 0) == 0) key = auth.substr(7);
  if (key.empty()) {
    if (const auto it = request.query.find("apikey"); it != request.query.end()) key = it->second;
  }
  return principal(key);
}

std::optional<Principal> ApiKeys::principal(std::string_view key) const {
  if (key.empty() || key.size() > kMaxKey) return std::nullopt;
  const std::string digest = sha256_hex(key);
  std::shared_lock lock(mutex_);
  const auto it = by_digest_.find(digest);
  if (it == by_digest_.end()) return std::nullopt;
  return it->second;
}

NewKey ApiKeys::create(const std::string& user, std::optional<Role> role, const std::string& label) {
  if (!valid_user_name(user))
    throw BadRequest("bad_user", "a user name is 1-64 characters of A-Z a-z 0-9 . _ - (not starting with _)");
  if (label.size() > 128) throw BadRequest("bad_label", "a key's label has at most 128 characters");
  for (const char c : label)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw BadRequest("bad_label", "a key's label may not hold control characters");
  std::lock_guard write(write_);
  Database& db = store_.db();
  UserStore users(db);
  Database::Transaction t(db);
  const double now = unix_now();
  if (const auto existing = users.user(user)) {
    if (role && existing->role != to_string(*role))
      throw Conflict("role_mismatch", "the user '" + user + "' is a " + existing->role + ", not a " +
                                          std::string(to_string(*role)) + ": leave out the role");
  } else {
    users.add_user(user, std::string(to_string(role.value_or(Role::viewer))), now);
  }
  const std::string key = random_token(32);
  const long long id = users.add_key(sha256_hex(key), user, label, now);
  const KeyInfo info = info_of(*users.key(id));
  t.commit();
  load();
  return {info, key};
}

KeyInfo ApiKeys::revoke(long long id) {
  std::lock_guard write(write_);
  Database& db = store_.db();
  UserStore users(db);
  Database::Transaction t(db);
  const auto row = users.key(id);
  if (!row) throw NotFound("no key " + std::to_string(id));
  if (row->role == "admin" && users.admin_keys() <= 1)
    throw Conflict("last_admin_key",
                   "key " + std::to_string(id) + " is the last admin key: make another admin key first");
  users.remove_key(id);
  t.commit();
  load();
  return info_of(*row);
}

void ApiKeys::confirm(const Principal& who) const {
  if (who.key_id == 0) return;  // a session or a test's principal: checked where it was made
  if (!UserStore(store_.db()).key(who.key_id))
    throw ApiError(401, "unauthorized", "this API key was revoked: use another");
}

std::vector<KeyInfo> ApiKeys::list() const {
  std::vector<KeyInfo> out;
  for (const KeyRow& row : UserStore(store_.db()).keys()) out.push_back(info_of(row));
  return out;
}

std::optional<KeyInfo> ApiKeys::find(long long id) const {
  const auto row = UserStore(store_.db()).key(id);
  if (!row) return std::nullopt;
  return info_of(*row);
}

std::optional<Role> ApiKeys::role_of(const std::string& user) const {
  const auto row = UserStore(store_.db()).user(user);
  if (!row) return std::nullopt;
  return role_from(row->role);
}

bool ApiKeys::has_keys(const std::string& user) const {
  std::shared_lock lock(mutex_);
  for (const auto& [digest, p] : by_digest_)
    if (p.user == user) return true;
  return false;
}

}  // namespace salient::server
