// AppKeyRequests: OctoPrint's application-key workflow (its appkeys plugin). An app asks for a
// key without one (POST /plugin/appkeys/request) and polls with its app token; a person with an
// admin key sees the request (by its user token) and approves or denies it; the app's next poll
// gets the key. In memory, as OctoPrint keeps them; bounded, since anyone may ask: each address
// may ask 3 times a minute and 10 times an hour and have 2 requests waiting, one network (a /24,
// an IPv6 /64) 8, all together 64; so a few addresses cannot take every slot and leave the next
// app 429. A request lives 10 minutes (OctoPrint's cutoff) and goes after 20 s without a poll
// (apps poll every second or so).
// OctoPrint keeps requests in memory; here they are in the database (table app_key_requests), so
// that in a farm an app asks through one node, an admin decides on another and the app's poll,
// through either, gets the key, once. The rate of asking is counted per node (in memory); what
// waits is bounded across the farm.
// Time is passed in (Unix seconds: the nodes share it), so that tests need not wait.
#pragma once

#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/http/principal.hpp"

namespace salient::server {

class Store;

struct AppKeyRequest {
  std::string app, user;  // user: whom the app asked a key for ("" for anyone)
  std::string remote;     // the asking address
  std::string app_token;  // only from open(): the database keeps its digest
  std::string user_token;
  double created = 0, polled = 0;
  // Once decided: approved, for whom and with which role (a new user's).
  bool decided = false;
  std::string key_user;
  std::optional<Role> key_role;
};

class AppKeyRequests {
 public:
  static constexpr std::size_t kMaxPending = 64;
  static constexpr std::size_t kPerAddress = 2, kPerNetwork = 8;  // waiting at once
  static constexpr double kLifetime = 600;    // seconds a request (or an unfetched approval) lives
  static constexpr double kPollTimeout = 20;  // seconds without a poll before a request goes
  static constexpr std::size_t kPerMinute = 3, kPerHour = 10;

  // Each call throws StoreError when the database cannot be reached.
  explicit AppKeyRequests(Store& store) : store_(store) {}

  // The new request with its app token and user token; TooBusy when full, when `remote` (or its network)
  // has its share waiting, or when it asks too often.
  AppKeyRequest open(const std::string& app, const std::string& user, const std::string& remote, double now);

  enum class Poll { pending, approved, unknown };
  struct PollResult {
    Poll state = Poll::unknown;
    AppKeyRequest request;  // when approved: whom the key is for; the request is then gone
  };
  PollResult poll(const std::string& app_token, double now);
  // Approves (the key for `key_user`, made with `role` if the user is new) or denies the request
  // of that user token (or app token). False: no such pending request.
  bool decide(const std::string& token, bool approve, const std::string& key_user, std::optional<Role> role,
              double now);
  std::optional<AppKeyRequest> pending(const std::string& token, double now);
  std::vector<AppKeyRequest> pending(double now);

 private:
  Store& store_;
  std::mutex mutex_;                                  // guards asked_
  std::deque<std::pair<std::string, double>> asked_;  // (address, when), the last hour, bounded
};

}  // namespace salient::server
