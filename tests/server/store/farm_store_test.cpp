// The farm's registry (nodes, their printers, liveness), the dead nodes' prints, and requests
// carried between nodes: on SQLite and, in server_store_pg_tests, on PostgreSQL with several
// connections at once (each thread its own, as each node has).
#include "server/store/farm_store.hpp"

#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <thread>

#include "server/printers/printer_service.hpp"
#include "server/store/print_store.hpp"
#include "server/store/queue_store.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;
using salient::test::test_database;

TEST_CASE("farm registry: a node's printers with its heartbeat, and a live node's printer id is refused") {
  const salient::test::ScratchDir scratch("farm-registry");
  Database db(test_database(scratch));
  FarmStore farm(db);
  farm.heartbeat({"x", "printers", "1", 100, 100});
  farm.register_printers("x", {{"x1", "generic-i3", R"({"state":"operational"})"}}, 100, 85);
  farm.heartbeat({"y", "api,slicer", "1", 100, 101});
  const auto printers = farm.printers();
  REQUIRE(printers.size() == 1);
  CHECK(printers[0].node == "x");
  CHECK(printers[0].heartbeat_at == 100);
  CHECK(farm.profile_live("generic-i3", 90));
  CHECK_FALSE(farm.profile_live("generic-i3", 101));  // x's heartbeat is older than that
  CHECK_FALSE(farm.profile_live("replicator2x", 0));

  // y claims x1 while x is live: refused, both nodes named.
  try {
    farm.register_printers("y", {{"x1", "generic-i3", "{}"}}, 102, 90);
    FAIL("a live node's printer id was registered again");
  } catch (const StoreError& e) {
    const std::string why = e.what();
    CHECK(why.find("'x1'") != std::string::npos);
    CHECK(why.find("'x'") != std::string::npos);
    CHECK(why.find("'y'") != std::string::npos);
  }
  CHECK(farm.printer("x1")->node == "x");
  // x renews; a status change is written; x restarting re-registers its own printers freely.
  farm.set_status("x1", "x", R"({"state":"printing"})", 103);
  CHECK(farm.printer("x1")->status == R"({"state":"printing"})");
  farm.set_status("x1", "y", R"({"state":"forged"})", 104);  // not y's printer: nothing
  CHECK(farm.printer("x1")->status == R"({"state":"printing"})");
  farm.register_printers("x", {{"x1", "generic-i3", "{}"}, {"x2", "generic-i3", "{}"}}, 105, 90);
  CHECK(farm.printers().size() == 2);
  farm.register_printers("x", {{"x2", "generic-i3", "{}"}}, 106, 90);  // x1 removed from x's config
  CHECK_FALSE(farm.printer("x1"));
  // Once x is dead (heartbeat older than the lease), y may take its printer id.
  farm.register_printers("y", {{"x2", "generic-i3", "{}"}}, 200, 185);
  CHECK(farm.printer("x2")->node == "y");
  CHECK(farm.nodes().size() == 2);
}

TEST_CASE("farm clock: the database's, and every heartbeat's age read on it") {
  const salient::test::ScratchDir scratch("farm-clock");
  Database db(test_database(scratch));
  FarmStore farm(db);
  const double host =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  const double now = farm.clock();
  CHECK(std::abs(now - host) < 5);  // the same host here: the database's clock is the host's
  CHECK(farm.clock() >= now);
  CHECK(farm.heartbeat({"x", "printers", "1", now, now - 100}));        // a new row
  CHECK_FALSE(farm.heartbeat({"x", "printers", "1", now, now - 100}));  // renewed
  farm.register_printers("x", {{"x1", "generic-i3", "{}"}}, now, now - 15);
  const auto x = farm.node("x");
  REQUIRE(x);
  CHECK(x->heartbeat_age >= 100);
  CHECK(x->heartbeat_age < 110);
  CHECK(farm.printer("x1")->heartbeat_age == doctest::Approx(farm.node("x")->heartbeat_age).epsilon(0.01));
  CHECK(farm.nodes().at(0).heartbeat_age >= 100);
}

TEST_CASE(
    "farm: a retired node is forgotten only when dead: its printers go and its prints stay until it comes "
    "back") {
  const salient::test::ScratchDir scratch("farm-forget");
  Store store(scratch.path, test_database(scratch));
  FarmStore farm(store.db());
  const double now = farm.clock();
  farm.heartbeat({"x", "printers", "1", now, now});
  farm.register_printers("x", {{"x1", "generic-i3", "{}"}}, now, now - 15);
  farm.heartbeat({"y", "api", "1", now, now});
  PrintStore prints(store.db());
  const long long print = prints.create("x1", std::nullopt, "d", "a.gcode", 10, now).id;
  const long long pending =
      farm.post({0, "x", "POST", "/api/v1/printers/x1/pause", "", "admin", "admin"}, now);

  CHECK(farm.forget("nobody", 15) == FarmStore::Forget::unknown);
  CHECK(farm.forget("x", 15) == FarmStore::Forget::alive);  // its heartbeat is fresh
  CHECK(farm.printer("x1"));
  farm.heartbeat({"x", "printers", "1", now, now - 60});  // silent for a minute
  CHECK(farm.forget("x", 15) == FarmStore::Forget::forgotten);
  CHECK_FALSE(farm.node("x"));
  CHECK_FALSE(farm.printer("x1"));
  CHECK(farm.nodes().size() == 1);
  CHECK(prints.get(print));                                 // the history keeps its prints
  CHECK(farm.take("x", 16).empty());                        // a request nobody will answer is cancelled…
  CHECK_FALSE(farm.answer(pending, {200, "[]", ""}, now));  // …and answered by nobody
  CHECK(farm.forget("x", 15) == FarmStore::Forget::unknown);
  // The node comes back: its heartbeat makes the row again and says so (its printers register).
  CHECK(farm.heartbeat({"x", "printers", "1", now, farm.clock()}));
  CHECK(farm.node("x"));
}

TEST_CASE(
    "farm: a dead node's running prints are interrupted by the others, once, and a start marks only its "
    "own") {
  const salient::test::ScratchDir scratch("farm-dead");
  Store store(scratch.path, test_database(scratch));
  FarmStore farm(store.db());
  PrintStore prints(store.db());
  farm.heartbeat({"x", "printers", "1", 100, 100});
  farm.heartbeat({"z", "printers", "1", 100, 100});
  farm.register_printers("x", {{"x1", "p", "{}"}}, 100, 85);
  farm.register_printers("z", {{"z1", "p", "{}"}}, 100, 85);
  const PrintRecord on_x = prints.create("x1", std::nullopt, "d", "a.gcode", 100, 100);
  prints.set_progress(on_x.id, PrintState::paused, 40, {});
  const PrintRecord on_z = prints.create("z1", std::nullopt, "d", "b.gcode", 100, 100);
  farm.heartbeat({"z", "printers", "1", 100, 120});  // z lives on, x is silent
  CHECK(farm.interrupt_dead("y", 110, 121) == 1);
  CHECK(prints.get(on_x.id)->state == PrintState::interrupted);
  CHECK(prints.get(on_x.id)->confirmed == 40);  // resumable from there
  CHECK(prints.get(on_z.id)->state == PrintState::printing);
  CHECK(farm.interrupt_dead("y", 110, 122) == 0);  // idempotent
  // A node never marks its own, whatever its heartbeat says.
  const PrintRecord again = prints.create("x1", std::nullopt, "d", "c.gcode", 100, 130);
  CHECK(farm.interrupt_dead("x", 115, 131) == 0);
  CHECK(prints.get(again.id)->state == PrintState::printing);

  // The PrinterService of a node starting on PostgreSQL (a farm) marks only its printers' prints
  // (here none: z's go on); on SQLite (one node) every unfinished print, as always.
  DaemonConfig config;
  config.printers.clear();
  PrinterService service(config, store);
  if (salient::test::on_postgresql())
    CHECK(prints.get(on_z.id)->state == PrintState::printing);
  else
    CHECK(prints.get(on_z.id)->state == PrintState::interrupted);
}

TEST_CASE("farm requests: each taken once by its node, a cancelled one never, an answer only once taken") {
  const salient::test::ScratchDir scratch("farm-requests");
  Store store(scratch.path, test_database(scratch));
  FarmStore farm(store.db());
  std::vector<long long> ids;
  for (int i = 0; i < 40; ++i)
    ids.push_back(
        farm.post({0, i % 2 ? "x" : "z", "POST", "/api/v1/printers/x1/pause", "{}", "alice", "operator"}, 1));
  CHECK(farm.cancel(ids[0]));  // z's first: the caller gave up
  std::mutex mutex;
  std::multiset<long long> taken;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      FarmStore mine(store.db());  // this thread's connection
      for (int round = 0; round < 10; ++round)
        for (const PrinterRequest& r : mine.take(t % 2 ? "x" : "z", 3)) {
          std::lock_guard lock(mutex);
          taken.insert(r.id);
          CHECK(r.user == "alice");
          CHECK(r.role == "operator");
          CHECK(r.node == (t % 2 ? "x" : "z"));
        }
    });
  for (auto& t : threads) t.join();
  CHECK(taken.size() == 39);
  CHECK(std::set<long long>(taken.begin(), taken.end()).size() == 39);
  CHECK_FALSE(taken.count(ids[0]));
  CHECK_FALSE(farm.answer(ids[0], {200, "[]", "late"}, 2));  // cancelled: its answer is dropped
  CHECK_FALSE(farm.answer_of(ids[0]));
  CHECK_FALSE(farm.cancel(ids[1]));  // taken: its node runs it, a cancel cannot undo that
  CHECK(farm.answer(ids[1], {202, R"([["Location","/x"]])", R"({"state":"paused"})"}, 2));
  CHECK(farm.answer_of(ids[1])->status == 202);
  CHECK(farm.answer_of(ids[1])->body == R"({"state":"paused"})");
  CHECK_FALSE(farm.answer(ids[1], {500, "[]", ""}, 3));  // answered once
  CHECK(farm.purge(10) == 2);                            // the answered and the cancelled
}

TEST_CASE("farm queue: entries taken by several nodes at once are each taken once") {
  const salient::test::ScratchDir scratch("farm-take");
  Store store(scratch.path, test_database(scratch));
  for (int i = 0; i < 30; ++i)
    QueueStore(store.db()).add("profile/p", "file", std::to_string(i) + ".gcode", i);
  std::mutex mutex;
  std::multiset<long long> taken;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      QueueStore queue(store.db());
      for (int round = 0; round < 10; ++round)
        for (const QueueEntry& e : queue.list("profile/p"))
          if (queue.remove("profile/p", e.id)) {  // the take PrinterService makes before a start
            std::lock_guard lock(mutex);
            taken.insert(e.id);
          }
    });
  for (auto& t : threads) t.join();
  CHECK(taken.size() == 30);
  CHECK(std::set<long long>(taken.begin(), taken.end()).size() == 30);
}
