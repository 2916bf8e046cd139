// Database::notify / listen / wait_notification: PostgreSQL's NOTIFY between two connections,
// sent at commit (never on rollback); a broken listening connection is reported; on SQLite (one
// node) they are a clear error.
#include <doctest/doctest.h>

#include <chrono>
#include <string>

#include "server/store/database.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;
using salient::test::test_database;
using namespace std::chrono_literals;

TEST_CASE("notify: a listening connection receives channel and payload, and not other channels") {
  const salient::test::ScratchDir scratch("notify");
  Database sender(test_database(scratch));
  if (sender.dialect() == Dialect::sqlite) {
    CHECK_THROWS_WITH_AS(sender.notify("salient_events", "x"), doctest::Contains("need a PostgreSQL store"),
                         StoreError);
    CHECK_THROWS_AS(sender.listen("salient_events"), StoreError);
    return;
  }
  Database listener(test_database(scratch));
  listener.listen("salient_test");
  CHECK(!listener.wait_notification(50ms));
  sender.notify("other_channel", "not for us");
  sender.notify("salient_test", "hello {\"a\": 1}\nline two");
  const auto n = listener.wait_notification(5000ms);
  REQUIRE(n);
  CHECK(n->channel == "salient_test");
  CHECK(n->payload == "hello {\"a\": 1}\nline two");
  CHECK(!listener.wait_notification(100ms));
  // The listener may still run queries between waits.
  auto q = listener.prepare("SELECT 41 + 1");
  REQUIRE(q.step());
  CHECK(q.integer(0) == 42);
}

TEST_CASE("notify: bad channel names and payloads of 8000 bytes or more are refused") {
  const salient::test::ScratchDir scratch("notify-bad");
  Database db(test_database(scratch));
  if (db.dialect() == Dialect::sqlite) return;
  for (const char* channel : {"", "Upper", "a-b", "x\"; DROP TABLE jobs; --"})
    CHECK_THROWS_AS(db.notify(channel, "x"), StoreError);
  CHECK_THROWS_AS(db.listen("a b"), StoreError);
  CHECK_THROWS_WITH_AS(db.notify("ok", std::string(8000, 'x')), doctest::Contains("at most 7999"),
                       StoreError);
  CHECK_NOTHROW(db.notify("ok", std::string(7999, 'x')));
}

TEST_CASE("notify inside a transaction: delivered at its commit, not at all on rollback") {
  const salient::test::ScratchDir scratch("notify-tx");
  Database sender(test_database(scratch));
  if (sender.dialect() == Dialect::sqlite) return;
  Database listener(test_database(scratch));
  listener.listen("salient_test");
  {
    Database::Transaction t(sender);
    sender.notify("salient_test", "rolled back");
  }
  {
    Database::Transaction t(sender);
    sender.notify("salient_test", "committed 1");
    sender.notify("salient_test", "committed 2");
    CHECK(!listener.wait_notification(200ms));  // not before the commit
    t.commit();
  }
  auto a = listener.wait_notification(5000ms), b = listener.wait_notification(5000ms);
  REQUIRE(a);
  REQUIRE(b);
  CHECK(a->payload == "committed 1");
  CHECK(b->payload == "committed 2");
  CHECK(!listener.wait_notification(200ms));
}

TEST_CASE("listen: a terminated backend is reported as a StoreError, and a new connection listens again") {
  const salient::test::ScratchDir scratch("notify-kill");
  Database admin(test_database(scratch));
  if (admin.dialect() == Dialect::sqlite) return;
  auto listener = std::make_unique<Database>(test_database(scratch));
  listener->listen("salient_test");
  auto pid = listener->prepare("SELECT pg_backend_pid()");
  REQUIRE(pid.step());
  const std::int64_t backend = pid.integer(0);
  pid.run();
  auto kill = admin.prepare("SELECT pg_terminate_backend(CAST(? AS INT))");
  kill.bind(1, backend).run();
  CHECK_THROWS_WITH_AS(
      {
        for (int i = 0; i < 50; ++i) listener->wait_notification(100ms);
      },
      doctest::Contains("connection was lost"), StoreError);
  listener = std::make_unique<Database>(test_database(scratch));
  listener->listen("salient_test");
  admin.notify("salient_test", "after");
  const auto n = listener->wait_notification(5000ms);
  REQUIRE(n);
  CHECK(n->payload == "after");
}
