// OctoPrint's application-key requests: pending until decided, approved once, denied or
// expired as gone; bounded in number and rate, since anyone may ask.
#include "server/api/app_key_requests.hpp"

#include <doctest/doctest.h>

#include <regex>

#include "server/common/domain_error.hpp"

using namespace salient::server;
using Poll = AppKeyRequests::Poll;

TEST_CASE("a request is pending, then approved once, and a denied one is gone") {
  AppKeyRequests requests;
  const AppKeyRequest cura = requests.open("Cura", "", "10.0.0.2", 0);
  CHECK(std::regex_match(cura.app_token, std::regex("^[A-Za-z0-9_-]{43}$")));
  CHECK(cura.user_token != cura.app_token);
  CHECK(requests.poll(cura.app_token, 1).state == Poll::pending);
  CHECK(requests.poll(cura.user_token, 1).state == Poll::unknown);  // the app polls with its own token
  REQUIRE(requests.pending(2).size() == 1);
  CHECK(requests.pending(2)[0].app == "Cura");
  CHECK(requests.decide(cura.user_token, true, "apps", Role::operator_, 3));
  CHECK_FALSE(requests.decide(cura.user_token, false, "apps", std::nullopt, 3));  // decided already
  CHECK(requests.pending(4).empty());
  const auto approved = requests.poll(cura.app_token, 5);
  CHECK(approved.state == Poll::approved);
  CHECK(approved.request.key_user == "apps");
  CHECK(approved.request.key_role == Role::operator_);
  CHECK(requests.poll(cura.app_token, 6).state == Poll::unknown);  // the key is handed out once

  const AppKeyRequest pod = requests.open("OctoPod", "vic", "10.0.0.3", 10);
  CHECK(requests.decide(pod.app_token, false, "vic", std::nullopt, 11));  // by either token
  CHECK(requests.poll(pod.app_token, 12).state == Poll::unknown);
}

TEST_CASE("requests expire: after 10 minutes, or a minute without a poll") {
  AppKeyRequests requests;
  const AppKeyRequest a = requests.open("a", "", "h1", 0);
  const AppKeyRequest b = requests.open("b", "", "h2", 0);
  for (double t = 30; t < 700; t += 30) requests.poll(a.app_token, t);  // a keeps polling, b does not
  CHECK(requests.poll(b.app_token, 700).state == Poll::unknown);
  CHECK(requests.poll(a.app_token, 700).state == Poll::unknown);  // past 600 s even so
  const AppKeyRequest c = requests.open("c", "", "h3", 1000);
  CHECK(requests.poll(c.app_token, 1050).state == Poll::pending);
  CHECK(requests.poll(c.app_token, 1111).state == Poll::unknown);
  CHECK_FALSE(requests.decide(c.user_token, true, "apps", std::nullopt, 1111));
}

TEST_CASE("bounded: 3 a minute and 10 an hour per address, 16 waiting in all") {
  AppKeyRequests requests;
  for (int i = 0; i < 3; ++i) requests.open("x", "", "attacker", i);
  CHECK_THROWS_AS(requests.open("x", "", "attacker", 3), TooBusy);
  requests.open("x", "", "someone", 3);  // others may still ask
  std::vector<AppKeyRequest> open;
  for (int i = 0; i < 7; ++i) requests.open("x", "", "attacker", 61 + 61 * i);
  CHECK_THROWS_AS(requests.open("x", "", "attacker", 3000), TooBusy);  // 10 in the hour
  AppKeyRequests fresh;
  for (std::size_t i = 0; i < AppKeyRequests::kMaxPending; ++i)
    fresh.open("x", "", "10.1.0." + std::to_string(i), 0);
  try {
    fresh.open("x", "", "10.2.0.1", 1);
    FAIL("a request beyond the bound was taken");
  } catch (const TooBusy& e) {
    CHECK(e.retry_after().value_or(0) > 0);
  }
  CHECK(fresh.pending(1).size() == AppKeyRequests::kMaxPending);
}
