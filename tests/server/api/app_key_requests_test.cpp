// OctoPrint's application-key requests: pending until decided, approved once, denied or
// expired as gone; bounded in number and rate, since anyone may ask.
#include "server/api/app_key_requests.hpp"

#include <doctest/doctest.h>

#include <regex>

#include "server/common/domain_error.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
using Poll = AppKeyRequests::Poll;

namespace {

// The requests of a daemon with a database of its own.
struct Node {
  explicit Node(const std::string& name) : dir("appkeys-" + name), store(dir.path), requests(store) {}
  salient::test::ScratchDir dir;
  Store store;
  AppKeyRequests requests;
};

}  // namespace

TEST_CASE("a request is pending, then approved once, and a denied one is gone") {
  Node requests_node("t2");
  AppKeyRequests& requests = requests_node.requests;
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

TEST_CASE("requests expire: after 10 minutes, or 20 s without a poll") {
  Node requests_node("t3");
  AppKeyRequests& requests = requests_node.requests;
  const AppKeyRequest a = requests.open("a", "", "h1", 0);
  const AppKeyRequest b = requests.open("b", "", "h2", 0);
  for (double t = 10; t < 700; t += 10) requests.poll(a.app_token, t);  // a keeps polling, b does not
  CHECK(requests.poll(b.app_token, 700).state == Poll::unknown);
  CHECK(requests.poll(a.app_token, 700).state == Poll::unknown);  // past 600 s even so
  const AppKeyRequest c = requests.open("c", "", "h3", 1000);
  CHECK(requests.poll(c.app_token, 1015).state == Poll::pending);
  CHECK(requests.poll(c.app_token, 1036).state == Poll::unknown);
  CHECK_FALSE(requests.decide(c.user_token, true, "apps", std::nullopt, 1036));
}

TEST_CASE("bounded: 3 a minute and 10 an hour per address, 2 waiting per address") {
  Node requests_node("t4");
  AppKeyRequests& requests = requests_node.requests;
  const AppKeyRequest first = requests.open("x", "", "attacker", 0);
  requests.open("x", "", "attacker", 1);
  CHECK_THROWS_AS(requests.open("x", "", "attacker", 2), TooBusy);  // 2 waiting
  CHECK(requests.decide(first.user_token, false, "", std::nullopt, 2));
  requests.open("x", "", "attacker", 2);
  CHECK_THROWS_AS(requests.open("x", "", "attacker", 3), TooBusy);              // 3 in the minute
  requests.open("x", "", "someone", 3);                                         // others may still ask
  for (int i = 0; i < 7; ++i) requests.open("x", "", "attacker", 61 + 61 * i);  // each expired unpolled
  CHECK_THROWS_AS(requests.open("x", "", "attacker", 3000), TooBusy);           // 10 in the hour
}

// The flood of issue 32: 7 addresses asking as fast as allowed, polling to keep their requests,
// left every other app 429 for 10 minutes. Now they hold 2 each at most and their network 8.
TEST_CASE("a flood from a few addresses leaves room for other apps") {
  Node requests_node("t5");
  AppKeyRequests& requests = requests_node.requests;
  std::vector<AppKeyRequest> flood;
  for (double t = 0; t < 600; t += 10) {
    for (int a = 1; a <= 7; ++a) {
      try {
        flood.push_back(requests.open("x", "", "10.1.0." + std::to_string(a), t));
      } catch (const TooBusy&) {
      }
    }
    for (const AppKeyRequest& r : flood) requests.poll(r.app_token, t);  // kept alive
    CHECK(requests.pending(t).size() <= AppKeyRequests::kPerNetwork);
  }
  // At 605 s the first requests (made at 0) have lived their 10 minutes: the flood asks again.
  for (int a = 1; a <= 7; ++a) {
    try {
      flood.push_back(requests.open("x", "", "10.1.0." + std::to_string(a), 605));
    } catch (const TooBusy&) {
    }
  }
  CHECK(requests.pending(605).size() == AppKeyRequests::kPerNetwork);
  // An app elsewhere (another network, or another address of the same one while it has room).
  const AppKeyRequest other = requests.open("OctoPod", "", "192.168.5.20", 605);
  CHECK(requests.poll(other.app_token, 606).state == Poll::pending);
  // The network's share full: a further address of it waits, with a time to retry.
  try {
    requests.open("x", "", "10.1.0.99", 606);
    FAIL("a request beyond the network's share was taken");
  } catch (const TooBusy& e) {
    CHECK(e.retry_after().value_or(0) > 0);
    CHECK(std::string(e.what()).find("network") != std::string::npos);
  }
  // IPv6: a /64 is one network; IPv4 mapped into IPv6 is the IPv4 address's.
  Node six_node("t6");
  AppKeyRequests& six = six_node.requests;
  for (int i = 0; i < 8; ++i) six.open("x", "", "2001:db8:1:2::" + std::to_string(i + 1), 0);
  CHECK_THROWS_AS(six.open("x", "", "2001:db8:1:2:ffff::1", 0), TooBusy);
  six.open("x", "", "2001:db8:1:3::1", 0);
  Node mapped_node("t7");
  AppKeyRequests& mapped = mapped_node.requests;
  for (int i = 0; i < 8; ++i) mapped.open("x", "", "::ffff:10.9.9." + std::to_string(i + 1), 0);
  CHECK_THROWS_AS(mapped.open("x", "", "10.9.9.200", 0), TooBusy);
}

TEST_CASE("bounded: 64 waiting in all") {
  Node requests_node("t8");
  AppKeyRequests& requests = requests_node.requests;
  for (std::size_t i = 0; i < AppKeyRequests::kMaxPending; ++i)
    requests.open("x", "", "10." + std::to_string(i) + ".0.1", 0);
  try {
    requests.open("x", "", "10.200.0.1", 1);
    FAIL("a request beyond the bound was taken");
  } catch (const TooBusy& e) {
    CHECK(e.retry_after().value_or(0) > 0);
  }
  CHECK(requests.pending(1).size() == AppKeyRequests::kMaxPending);
}

// Issue 32: requests lived in each node's memory, so an app that asked through one node of a farm
// and polled through another (a load balancer) was never paired. Two AppKeyRequests on one
// database are two nodes.
TEST_CASE("an app asks through one node, an admin decides on another, the app's key comes once") {
  Node a("farm");
  Store b_store(a.dir.path);
  AppKeyRequests b(b_store);
  const AppKeyRequest cura = a.requests.open("Cura", "otto", "10.0.0.2", 100);
  CHECK(b.poll(cura.app_token, 101).state == Poll::pending);
  const auto listed = b.pending(102);
  REQUIRE(listed.size() == 1);
  CHECK(listed[0].app == "Cura");
  CHECK(listed[0].user == "otto");
  CHECK(listed[0].remote == "10.0.0.2");
  CHECK(listed[0].app_token.empty());  // never read back: the database keeps its digest
  CHECK(b.decide(listed[0].user_token, true, "otto", Role::operator_, 103));
  const auto approved = a.requests.poll(cura.app_token, 104);
  CHECK(approved.state == Poll::approved);
  CHECK(approved.request.key_user == "otto");
  CHECK(approved.request.key_role == Role::operator_);
  CHECK(b.poll(cura.app_token, 105).state == Poll::unknown);  // handed out once, on either node
  // The waiting bound holds across nodes: an address's third request is refused on the other.
  a.requests.open("x", "", "10.7.0.1", 200);
  b.open("x", "", "10.7.0.1", 201);
  CHECK_THROWS_AS(a.requests.open("x", "", "10.7.0.1", 202), TooBusy);
  // What is kept is no secret: the app's token is not in the database, only its digest.
  auto q = a.store.db().prepare("SELECT app_token_digest FROM app_key_requests");
  while (q.step()) CHECK(q.text(0).size() == 64);
}
