// Requests for another node's printer, carried through the store: run on the owning node's router
// as the caller who sent them (no key checked there), answered with its status, headers and body;
// 503 for a dead node, 504 for a silent one (the request then never runs), 413 for a big body.
// On SQLite and, in server_store_pg_tests, on PostgreSQL.
#include "server/api/printer_forwarding.hpp"

#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "server/api/api_json.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

HttpRequest pause_request(Role role, std::string body = "") {
  HttpRequest r;
  r.method = "POST";
  r.target = "/api/v1/printers/x1/pause?why=test";
  r.path = "/api/v1/printers/x1/pause";
  r.body = std::move(body);
  r.caller = Principal{"otto", role, 7};
  return r;
}

}  // namespace

TEST_CASE(
    "forwarding: a request for another node's printer runs there as its caller, its answer comes back") {
  const salient::test::ScratchDir scratch("forwarding");
  Store store(scratch.path, salient::test::test_database(scratch));
  const double now = now_seconds();
  FarmStore(store.db()).heartbeat({"x", "printers", "1", now, now});
  FarmStore(store.db()).register_printers("x", {{"x1", "generic-i3", "{}"}}, now, now - 15);

  std::atomic<int> ran{0};
  Router x_router;  // node x's: it refuses every key, so nothing forwarded may be authenticated again
  x_router.set_authenticator([](const HttpRequest&) { return std::optional<Principal>(); });
  x_router.add(
      "POST", "/api/v1/printers/{id}/pause", Access::key, [&ran](const HttpRequest& r, const PathParams& p) {
        ++ran;
        HttpResponse out =
            json_response(202, {{"id", p.at("id")}, {"by", r.caller->user}, {"why", r.query.at("why")}});
        out.headers.emplace_back("Location", "/api/v1/printers/x1");
        return out;
      });
  PrinterRequestExecutor x_executor(store, x_router, "x");
  x_executor.start();
  PrinterFarm y(store, {"y", 15, 5, 64, 4});
  const auto x1 = y.other("x1");
  REQUIRE(x1);
  CHECK(x1->node == "x");
  CHECK(y.live(*x1));
  CHECK_FALSE(y.other("nope"));

  const HttpResponse out = y.forward(pause_request(Role::operator_), *x1);
  CHECK(out.status == 202);
  CHECK(out.content_type == "application/json");
  const auto body = nlohmann::json::parse(out.body);
  CHECK(body["by"] == "otto");
  CHECK(body["why"] == "test");
  REQUIRE(out.headers.size() == 1);
  CHECK(out.headers[0].second == "/api/v1/printers/x1");
  CHECK(y.forward(pause_request(Role::viewer), *x1).status == 403);  // x checks the role too
  CHECK(y.forward(pause_request(Role::operator_, std::string(65, ' ')), *x1).status == 413);
  CHECK(ran == 1);

  // x silent: 504 naming it, and the request is cancelled: x, back, never runs it.
  x_executor.stop();
  PrinterFarm impatient(store, {"y", 15, 0.3, 64, 4});
  const HttpResponse late = impatient.forward(pause_request(Role::operator_), *x1);
  CHECK(late.status == 504);
  CHECK(late.body.find("'x'") != std::string::npos);
  PrinterRequestExecutor again(store, x_router, "x");
  again.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  again.stop();
  CHECK(ran == 1);

  // x dead (its heartbeat older than the lease): 503 naming it, nothing posted.
  FarmStore(store.db()).heartbeat({"x", "printers", "1", now, now - 60});
  const auto dead = y.other("x1");
  CHECK_FALSE(y.live(*dead));
  const HttpResponse refused = y.forward(pause_request(Role::operator_), *dead);
  CHECK(refused.status == 503);
  CHECK(refused.body.find("'x'") != std::string::npos);
}

TEST_CASE("forwarding on PostgreSQL wakes the owning node at once: it does not wait for its idle poll") {
  const salient::test::ScratchDir scratch("forwarding-wake");
  Store store(scratch.path, salient::test::test_database(scratch));
  if (store.db().dialect() != Dialect::postgresql) return;  // SQLite polls every kPoll: nothing to wake
  const double now = now_seconds();
  FarmStore(store.db()).heartbeat({"x", "printers", "1", now, now});
  FarmStore(store.db()).register_printers("x", {{"x1", "generic-i3", "{}"}}, now, now - 15);
  Router x_router;
  x_router.add("POST", "/api/v1/printers/{id}/pause", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(202, {{"paused", true}});
  });
  PrinterRequestExecutor x_executor(store, x_router, "x");
  x_executor.start();
  PrinterFarm y(store, {"y", 15, 5, 64, 4});
  const auto x1 = y.other("x1");
  REQUIRE(x1);
  CHECK(y.forward(pause_request(Role::operator_), *x1).status == 202);  // the executor is listening now
  // Ten requests: polled once a second (kIdlePoll) they took 10.0 s (each asked just after a poll);
  // woken, milliseconds each: the bound leaves room for a loaded machine under ASan.
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 10; ++i) CHECK(y.forward(pause_request(Role::operator_), *x1).status == 202);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(seconds < 4.0);
  MESSAGE("10 forwarded requests in " << seconds << " s");
}

TEST_CASE("forwarding: a request the owning node took but answers late is awaited, never told undone") {
  const salient::test::ScratchDir scratch("forwarding-slow");
  Store store(scratch.path, salient::test::test_database(scratch));
  const double now = now_seconds();
  FarmStore(store.db()).heartbeat({"x", "printers", "1", now, now});
  FarmStore(store.db()).register_printers("x", {{"x1", "generic-i3", "{}"}}, now, now - 15);
  std::atomic<int> ran{0};
  std::atomic<int> delay_ms{600};
  Router x_router;  // a print that takes longer to start than the API node's timeout
  x_router.add("POST", "/api/v1/printers/{id}/pause", Access::key,
               [&](const HttpRequest&, const PathParams&) {
                 std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms.load()));
                 ++ran;
                 return json_response(202, {{"paused", true}});
               });
  PrinterRequestExecutor x_executor(store, x_router, "x");
  x_executor.start();
  PrinterFarm y(store, {"y", 15, 0.4, 64, 4});
  const auto x1 = y.other("x1");
  REQUIRE(x1);
  // Taken at once, answered after 0.6 s: the answer, not a 504 claiming nothing was done (the
  // pause did happen).
  const HttpResponse slow = y.forward(pause_request(Role::operator_), *x1);
  CHECK(ran == 1);
  CHECK(slow.status == 202);
  CHECK(slow.body.find("nothing was done") == std::string::npos);

  // Answered after twice the timeout: 504, saying it may still happen; and it does.
  delay_ms = 1500;
  const HttpResponse later = y.forward(pause_request(Role::operator_), *x1);
  CHECK(later.status == 504);
  CHECK(later.body.find("nothing was done") == std::string::npos);
  CHECK(later.body.find("may still") != std::string::npos);
  x_executor.stop();  // waits for the request under way
  CHECK(ran == 2);
}
