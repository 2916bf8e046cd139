#include "server/api/app_key_requests.hpp"

#include <arpa/inet.h>

#include <algorithm>

#include "server/api/sessions.hpp"
#include "server/common/domain_error.hpp"
#include "server/store/sha256.hpp"
#include "server/store/store.hpp"

namespace salient::server {
namespace {

// Bound on the remembered asks: with more addresses than this asking within the hour, the
// oldest are forgotten (the pending bound still holds).
constexpr std::size_t kMaxAsked = 1024;

constexpr const char* kColumns =
    "user_token, app, user_name, remote, created_at, polled_at, decided, key_user, key_role";

AppKeyRequest request_of(const Database::Statement& q) {
  AppKeyRequest r;
  r.user_token = q.text(0);
  r.app = q.text(1);
  r.user = q.text(2);
  r.remote = q.text(3);
  r.created = q.real(4);
  r.polled = q.real(5);
  r.decided = q.integer(6) != 0;
  if (!q.null(7)) r.key_user = q.text(7);
  if (!q.null(8)) r.key_role = role_from(q.text(8));
  return r;
}

// Requests past their lifetime, and undecided ones not polled lately, are gone.
void expire(Database& db, double now) {
  db.prepare("DELETE FROM app_key_requests WHERE created_at < ? OR (decided = 0 AND polled_at < ?)")
      .bind(1, now - AppKeyRequests::kLifetime)
      .bind(2, now - AppKeyRequests::kPollTimeout)
      .run();
}

// The undecided request of either token (the app's, or the user token an admin is shown).
std::optional<AppKeyRequest> undecided(Database& db, const std::string& token) {
  auto q =
      db.prepare(std::string("SELECT ") + kColumns +
                 " FROM app_key_requests WHERE decided = 0 AND (user_token = ? OR app_token_digest = ?)");
  q.bind(1, std::string_view(token)).bind(2, std::string_view(sha256_hex(token)));
  if (!q.step()) return std::nullopt;
  AppKeyRequest r = request_of(q);
  q.run();
  return r;
}

// The network an address is in: its /24 (IPv4, also when mapped into IPv6) or /64; anything else
// (a name) is its own.
std::string network_of(const std::string& address) {
  unsigned char b[16];
  if (::inet_pton(AF_INET, address.c_str(), b) == 1) return std::string(reinterpret_cast<char*>(b), 3);
  if (::inet_pton(AF_INET6, address.c_str(), b) != 1) return address;
  static constexpr unsigned char mapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
  if (std::equal(b, b + 12, mapped)) return std::string(reinterpret_cast<char*>(b) + 12, 3);
  return "6" + std::string(reinterpret_cast<char*>(b), 8);
}

}  // namespace

AppKeyRequest AppKeyRequests::open(const std::string& app, const std::string& user, const std::string& remote,
                                   double now) {
  std::lock_guard lock(mutex_);
  while (!asked_.empty() && now - asked_.front().second > 3600) asked_.pop_front();
  std::size_t minute = 0, hour = 0;
  for (const auto& [address, when] : asked_)
    if (address == remote) ++hour, minute += now - when <= 60 ? 1 : 0;
  if (minute >= kPerMinute || hour >= kPerHour)
    throw TooBusy("too_many_requests", "too many key requests from " + remote + ": try again later",
                  minute >= kPerMinute ? 60 : 600);
  Database& db = store_.db();
  Database::Transaction t(db);  // writers one at a time: the counts hold until the insert
  expire(db, now);
  const std::string network = network_of(remote);
  std::size_t waiting = 0, from_address = 0, from_network = 0;
  auto q = db.prepare("SELECT remote FROM app_key_requests WHERE decided = 0");
  while (q.step()) {
    const std::string other = q.text(0);
    ++waiting;
    from_address += other == remote ? 1 : 0;
    from_network += network_of(other) == network ? 1 : 0;
  }
  const auto retry = static_cast<int>(kPollTimeout);
  if (from_address >= kPerAddress)
    throw TooBusy("too_many_requests",
                  remote + " has " + std::to_string(from_address) +
                      " key requests waiting for a decision already: decide those first",
                  retry);
  if (from_network >= kPerNetwork)
    throw TooBusy(
        "too_many_requests",
        "too many key requests from " + remote + "'s network are waiting for a decision: try again later",
        retry);
  if (waiting >= kMaxPending)
    throw TooBusy("too_many_requests", "too many key requests are waiting for a decision: try again later",
                  retry);
  AppKeyRequest r;
  r.app = app, r.user = user, r.remote = remote;
  r.app_token = random_token(32), r.user_token = random_token(32);
  r.created = r.polled = now;
  db.prepare(
        "INSERT INTO app_key_requests (app_token_digest, user_token, app, user_name, remote, created_at, "
        "polled_at) VALUES (?, ?, ?, ?, ?, ?, ?)")
      .bind(1, std::string_view(sha256_hex(r.app_token)))
      .bind(2, std::string_view(r.user_token))
      .bind(3, std::string_view(app))
      .bind(4, std::string_view(user))
      .bind(5, std::string_view(remote))
      .bind(6, now)
      .bind(7, now)
      .run();
  t.commit();
  if (asked_.size() >= kMaxAsked) asked_.pop_front();
  asked_.emplace_back(remote, now);
  return r;
}

AppKeyRequests::PollResult AppKeyRequests::poll(const std::string& app_token, double now) {
  Database& db = store_.db();
  Database::Transaction t(db);  // two nodes polling one approval: one gets the key
  expire(db, now);
  const std::string digest = sha256_hex(app_token);
  auto q =
      db.prepare(std::string("SELECT ") + kColumns + " FROM app_key_requests WHERE app_token_digest = ?");
  q.bind(1, std::string_view(digest));
  if (!q.step()) return {};
  PollResult out{Poll::pending, request_of(q)};
  q.run();
  if (out.request.decided) {  // handed out once
    out.state = Poll::approved;
    db.prepare("DELETE FROM app_key_requests WHERE app_token_digest = ?")
        .bind(1, std::string_view(digest))
        .run();
  } else {
    out.request.polled = now;
    db.prepare("UPDATE app_key_requests SET polled_at = ? WHERE app_token_digest = ?")
        .bind(1, now)
        .bind(2, std::string_view(digest))
        .run();
  }
  t.commit();
  return out;
}

bool AppKeyRequests::decide(const std::string& token, bool approve, const std::string& key_user,
                            std::optional<Role> role, double now) {
  Database& db = store_.db();
  Database::Transaction t(db);
  expire(db, now);
  const std::optional<AppKeyRequest> r = undecided(db, token);
  if (!r) return false;
  if (!approve)  // the app's next poll finds nothing: 404, as OctoPrint answers a denial
    db.prepare("DELETE FROM app_key_requests WHERE user_token = ?")
        .bind(1, std::string_view(r->user_token))
        .run();
  else
    db.prepare("UPDATE app_key_requests SET decided = 1, key_user = ?, key_role = ? WHERE user_token = ?")
        .bind(1, std::string_view(key_user))
        .bind(2, role ? std::optional<std::string>(std::string(to_string(*role))) : std::nullopt)
        .bind(3, std::string_view(r->user_token))
        .run();
  t.commit();
  return true;
}

std::optional<AppKeyRequest> AppKeyRequests::pending(const std::string& token, double now) {
  Database& db = store_.db();
  Database::Transaction t(db);
  expire(db, now);
  std::optional<AppKeyRequest> r = undecided(db, token);
  t.commit();
  return r;
}

std::vector<AppKeyRequest> AppKeyRequests::pending(double now) {
  Database& db = store_.db();
  Database::Transaction t(db);
  expire(db, now);
  std::vector<AppKeyRequest> out;
  auto q = db.prepare(std::string("SELECT ") + kColumns +
                      " FROM app_key_requests WHERE decided = 0 ORDER BY created_at, user_token");
  while (q.step()) out.push_back(request_of(q));
  t.commit();
  return out;
}

}  // namespace salient::server
