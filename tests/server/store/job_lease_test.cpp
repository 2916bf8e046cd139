// Jobs across nodes: claims, leases, reaping and the holder's finish (JobStore). Run on SQLite
// (server_store_tests) and on PostgreSQL (server_store_pg_tests), where claimers on their own
// connections really race each other.
#include <doctest/doctest.h>

#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "server/store/job_store.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;
using salient::test::test_database;

TEST_CASE("claims: threads with their own connections never get the same job, and get them all") {
  const salient::test::ScratchDir scratch("claims");
  Store store(scratch.path, test_database(scratch));
  constexpr int total = 80;
  for (int i = 0; i < total; ++i) JobStore(store.db()).create("m.obj", std::to_string(i), "{}", "s", i);
  std::mutex mutex;
  std::vector<std::string> claimed;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      JobStore jobs(store.db());  // this thread's own connection
      std::string node = "n";     // appended: GCC 12 warns falsely (-Wrestrict) on "n" + …
      node += std::to_string(t);
      for (;;) {
        auto j = jobs.claim(node, 30, 1000);
        if (!j) {
          // Nothing claimable now: the rows left may be those other claimers are taking.
          if (jobs.count(JobState::queued) == 0) return;
          continue;
        }
        CHECK(*j->node == node);
        CHECK(j->attempts == 1);
        std::lock_guard lock(mutex);
        claimed.push_back(j->id);
      }
    });
  for (auto& t : threads) t.join();
  CHECK(claimed.size() == total);
  CHECK(std::set<std::string>(claimed.begin(), claimed.end()).size() == total);
  CHECK(JobStore(store.db()).count(JobState::running) == total);
}

TEST_CASE(
    "leases: a renewed lease holds, an expired one is reaped to the queue with the reason, then fails at the "
    "cap") {
  const salient::test::ScratchDir scratch("leases");
  Database db(test_database(scratch));
  JobStore jobs(db);
  const std::string id = jobs.create("bunny.obj", "m", "{}", "s", 1).id;
  REQUIRE(jobs.claim("n1", 10, 100));
  CHECK(jobs.reap(3, 105).empty());
  const auto held = jobs.renew("n1", 10, 108);  // now until 118
  REQUIRE(held.size() == 1);
  CHECK(held[0].id == id);
  CHECK(held[0].attempts == 1);
  CHECK_FALSE(held[0].cancel_requested);
  CHECK(jobs.reap(3, 111).empty());
  auto reaped = jobs.reap(3, 119);
  REQUIRE(reaped.size() == 1);
  CHECK(reaped[0].id == id);
  CHECK(reaped[0].state == JobState::queued);
  CHECK_FALSE(reaped[0].node);
  CHECK_FALSE(reaped[0].lease_until);
  CHECK(jobs.reap(3, 130).empty());  // reaped once
  nlohmann::json requeues = nlohmann::json::parse(jobs.get(id)->requeues);
  REQUIRE(requeues.size() == 1);
  CHECK(requeues[0]["node"] == "n1");
  CHECK(requeues[0]["at"] == 119);
  CHECK(requeues[0]["reason"] == "node n1 stopped renewing its lease");
  CHECK(jobs.renew("n1", 10, 120).empty());  // n1 comes back: it no longer holds the job

  CHECK(jobs.claim("n2", 10, 200)->attempts == 2);
  CHECK(jobs.reap(3, 211).at(0).state == JobState::queued);
  CHECK(jobs.claim("n3", 10, 300)->attempts == 3);
  reaped = jobs.reap(3, 311);
  REQUIRE(reaped.size() == 1);
  const Job failed = *jobs.get(id);
  CHECK(failed.state == JobState::failed);
  CHECK(*failed.finished_at == 311);
  REQUIRE(failed.error);
  CHECK(failed.error->find("3 attempts") != std::string::npos);
  CHECK(failed.error->find("node n1 stopped renewing its lease") != std::string::npos);
  CHECK(failed.error->find("node n3 stopped renewing its lease") != std::string::npos);
  CHECK(nlohmann::json::parse(failed.requeues).size() == 3);
  CHECK_FALSE(jobs.claim("n1", 10, 400));  // not queued again
}

TEST_CASE("leases: several nodes reaping the same expired jobs at once change each job once") {
  const salient::test::ScratchDir scratch("reapers");
  Store store(scratch.path, test_database(scratch));
  constexpr int total = 30;
  {
    JobStore jobs(store.db());
    for (int i = 0; i < total; ++i) jobs.create("m.obj", std::to_string(i), "{}", "s", i);
    while (jobs.claim("dead", 5, 100)) {
    }
  }
  std::mutex mutex;
  std::vector<std::string> reaped;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      for (const Job& j : JobStore(store.db()).reap(3, 200)) {
        std::lock_guard lock(mutex);
        reaped.push_back(j.id);
      }
    });
  for (auto& t : threads) t.join();
  CHECK(reaped.size() == total);
  CHECK(std::set<std::string>(reaped.begin(), reaped.end()).size() == total);
  JobStore jobs(store.db());
  CHECK(jobs.count(JobState::queued) == total);
  for (const Job& j : jobs.list(std::nullopt, total, 0)) CHECK(nlohmann::json::parse(j.requeues).size() == 1);
}

TEST_CASE("finish: only the holder of the claim: a stale or duplicate finish changes nothing") {
  const salient::test::ScratchDir scratch("holder");
  Database db(test_database(scratch));
  JobStore jobs(db);
  const std::string id = jobs.create("bunny.obj", "m", "{}", "s", 1).id;
  REQUIRE(jobs.claim("n1", 10, 100));
  REQUIRE(jobs.reap(3, 111).size() == 1);  // n1 paused past its lease
  // n1 claims it again itself: a new claim (attempt 2); the first run's finish is stale.
  REQUIRE(jobs.claim("n1", 10, 112)->attempts == 2);
  CHECK_FALSE(jobs.finish(id, {"n1", 1}, JobState::done, std::nullopt, std::string("{}"), 113));
  CHECK_FALSE(jobs.finish(id, {"n2", 2}, JobState::done, std::nullopt, std::string("{}"), 113));
  Job j = *jobs.get(id);
  CHECK(j.state == JobState::running);
  CHECK_FALSE(j.result);
  CHECK(jobs.finish(id, {"n1", 2}, JobState::done, std::nullopt, std::string(R"({"layers": 3})"), 114));
  CHECK_FALSE(jobs.finish(id, {"n1", 2}, JobState::failed, std::string("again"), std::nullopt, 115));
  j = *jobs.get(id);
  CHECK(j.state == JobState::done);
  CHECK(*j.result == R"({"layers": 3})");
  CHECK_FALSE(j.error);
  CHECK_FALSE(j.lease_until);
  CHECK(jobs.reap(3, 1000).empty());  // a finished job has no lease to expire
}

TEST_CASE("cancel across nodes: a queued job at once, a running one through its node's renewal") {
  const salient::test::ScratchDir scratch("cancel");
  Database db(test_database(scratch));
  JobStore jobs(db);
  const std::string queued = jobs.create("a.obj", "m1", "{}", "s", 1).id;
  CHECK_FALSE(jobs.request_cancel(queued));  // not running: nothing to ask
  CHECK(jobs.cancel_queued(queued, 2));
  CHECK(jobs.get(queued)->state == JobState::cancelled);
  CHECK_FALSE(jobs.cancel_queued(queued, 3));
  const std::string running = jobs.create("b.obj", "m2", "{}", "s", 4).id;
  REQUIRE(jobs.claim("n1", 10, 5));
  CHECK_FALSE(jobs.cancel_queued(running, 6));
  CHECK(jobs.renew("n1", 10, 6).at(0).cancel_requested == false);
  CHECK(jobs.request_cancel(running));
  const auto held = jobs.renew("n1", 10, 7);
  REQUIRE(held.size() == 1);
  CHECK(held[0].cancel_requested);
  CHECK(jobs.finish(running, {"n1", 1}, JobState::cancelled, std::nullopt, std::nullopt, 8));
  CHECK(jobs.get(running)->state == JobState::cancelled);
}
