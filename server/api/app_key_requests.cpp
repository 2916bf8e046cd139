#include "server/api/app_key_requests.hpp"

#include <arpa/inet.h>

#include <algorithm>

#include "server/api/sessions.hpp"
#include "server/common/domain_error.hpp"

namespace salient::server {
namespace {

// Bound on the remembered asks: with more addresses than this asking within the hour, the
// oldest are forgotten (the pending bound still holds).
constexpr std::size_t kMaxAsked = 1024;

bool matches(const AppKeyRequest& r, const std::string& token) {
  return r.app_token == token || r.user_token == token;
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

void AppKeyRequests::expire(double now) {
  std::erase_if(requests_, [&](const AppKeyRequest& r) {
    return now - r.created > kLifetime || (!r.decided && now - r.polled > kPollTimeout);
  });
  while (!asked_.empty() && now - asked_.front().second > 3600) asked_.pop_front();
}

AppKeyRequest AppKeyRequests::open(const std::string& app, const std::string& user, const std::string& remote,
                                   double now) {
  std::lock_guard lock(mutex_);
  expire(now);
  std::size_t minute = 0, hour = 0;
  for (const auto& [address, when] : asked_)
    if (address == remote) ++hour, minute += now - when <= 60 ? 1 : 0;
  if (minute >= kPerMinute || hour >= kPerHour)
    throw TooBusy("too_many_requests", "too many key requests from " + remote + ": try again later",
                  minute >= kPerMinute ? 60 : 600);
  const std::string network = network_of(remote);
  std::size_t waiting = 0, from_address = 0, from_network = 0;
  for (const AppKeyRequest& r : requests_) {
    if (r.decided) continue;
    ++waiting;
    from_address += r.remote == remote ? 1 : 0;
    from_network += network_of(r.remote) == network ? 1 : 0;
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
  if (asked_.size() >= kMaxAsked) asked_.pop_front();
  asked_.emplace_back(remote, now);
  AppKeyRequest r;
  r.app = app, r.user = user, r.remote = remote;
  r.app_token = random_token(32), r.user_token = random_token(32);
  r.created = r.polled = now;
  requests_.push_back(r);
  return r;
}

AppKeyRequests::PollResult AppKeyRequests::poll(const std::string& app_token, double now) {
  std::lock_guard lock(mutex_);
  expire(now);
  const auto it = std::find_if(requests_.begin(), requests_.end(),
                               [&](const AppKeyRequest& r) { return r.app_token == app_token; });
  if (it == requests_.end()) return {};
  if (!it->decided) {
    it->polled = now;
    return {Poll::pending, *it};
  }
  PollResult out{Poll::approved, *it};  // handed out once
  requests_.erase(it);
  return out;
}

bool AppKeyRequests::decide(const std::string& token, bool approve, const std::string& key_user,
                            std::optional<Role> role, double now) {
  std::lock_guard lock(mutex_);
  expire(now);
  const auto it = std::find_if(requests_.begin(), requests_.end(),
                               [&](const AppKeyRequest& r) { return !r.decided && matches(r, token); });
  if (it == requests_.end()) return false;
  if (!approve) {
    requests_.erase(it);  // the app's next poll finds nothing: 404, as OctoPrint answers a denial
    return true;
  }
  it->decided = true;
  it->key_user = key_user;
  it->key_role = role;
  return true;
}

std::optional<AppKeyRequest> AppKeyRequests::pending(const std::string& token, double now) {
  std::lock_guard lock(mutex_);
  expire(now);
  for (const AppKeyRequest& r : requests_)
    if (!r.decided && matches(r, token)) return r;
  return std::nullopt;
}

std::vector<AppKeyRequest> AppKeyRequests::pending(double now) {
  std::lock_guard lock(mutex_);
  expire(now);
  std::vector<AppKeyRequest> out;
  for (const AppKeyRequest& r : requests_)
    if (!r.decided) out.push_back(r);
  return out;
}

}  // namespace salient::server
