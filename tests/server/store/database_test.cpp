#include "server/store/database.hpp"

#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <mutex>
#include <regex>
#include <set>
#include <thread>
#include <vector>

#include "server/store/job_store.hpp"
#include "server/store/migrations.hpp"
#include "server/store/queue_store.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

namespace fs = std::filesystem;
using namespace salient::server;
using salient::test::test_database;

TEST_CASE("a new database is migrated to the latest schema (SQLite: in WAL mode)") {
  const salient::test::ScratchDir scratch("new");
  Database db(test_database(scratch));
  CHECK(db.schema_version() == Database::latest_schema_version());
  if (db.dialect() == Dialect::sqlite) {
    auto mode = db.prepare("PRAGMA journal_mode");
    REQUIRE(mode.step());
    CHECK(mode.text(0) == "wal");
  }
  const char* tables = db.dialect() == Dialect::sqlite
                           ? "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = ?"
                           : "SELECT count(*) FROM information_schema.tables WHERE table_name = ?";
  for (const char* table :
       {"jobs", "prints", "printers", "api_keys", "files", "print_queue", "users", "folders", "settings"}) {
    auto q = db.prepare(tables);
    q.bind(1, std::string_view(table));
    REQUIRE(q.step());
    CHECK_MESSAGE(q.integer(0) == 1, table);
  }
}

TEST_CASE("rows survive reopening, constraints hold, transactions roll back unless committed") {
  const salient::test::ScratchDir scratch("rows");
  {
    Database db(test_database(scratch));
    db.prepare(
          "INSERT INTO jobs (id, state, filename, model_digest, settings, settings_digest, created_at) "
          "VALUES (?, 'queued', 'bunny.obj', 'm', '{}', 's', 1.5)")
        .bind(1, std::string_view("j1"))
        .run();
    CHECK_THROWS_AS(
        db.prepare(
              "INSERT INTO jobs (id, state, filename, model_digest, settings, settings_digest, created_at) "
              "VALUES ('j2', 'exploded', 'x', 'm', '{}', 's', 1)")
            .run(),
        StoreError);
    CHECK_FALSE(db.in_transaction());
    {
      Database::Transaction t(db);
      CHECK(db.in_transaction());
      db.exec("UPDATE jobs SET state = 'running'");
    }  // no commit: rolled back
    CHECK_FALSE(db.in_transaction());
  }
  Database again(test_database(scratch));
  CHECK(again.schema_version() == Database::latest_schema_version());
  auto q = again.prepare("SELECT id, state, filename, created_at, error FROM jobs");
  REQUIRE(q.step());
  CHECK(q.text(0) == "j1");
  CHECK(q.text(1) == "queued");
  CHECK(q.real(3) == 1.5);
  CHECK(q.null(4));
  CHECK_FALSE(q.step());
}

TEST_CASE("a Store made again on a data directory removed meanwhile starts empty on the same thread") {
  // Each thread's connections belong to the Store that opened them: a connection kept by path
  // outlived its Store here, and the next Store read the deleted database through it.
  const salient::test::ScratchDir scratch("store-again");
  const auto jobs = [](Store& store) {
    auto q = store.db().prepare("SELECT count(*) FROM jobs");
    q.step();
    return q.integer(0);
  };
  {
    Store first(scratch.path);
    first.db().exec(
        "INSERT INTO jobs (id, state, filename, model_digest, settings, settings_digest, created_at) "
        "VALUES ('j1', 'queued', 'bunny.obj', 'm', '{}', 's', 1.5)");
    CHECK(jobs(first) == 1);
  }
  std::filesystem::remove_all(scratch.path);
  Store second(scratch.path);
  CHECK(jobs(second) == 0);
  CHECK(std::filesystem::exists(scratch.path / "salient.db"));
}

TEST_CASE("a database from a newer salientd is refused with a reason, and bad SQL names itself") {
  const salient::test::ScratchDir scratch("newer");
  {
    Database db(test_database(scratch));
    db.exec(db.dialect() == Dialect::sqlite ? "PRAGMA user_version = 99"
                                            : "UPDATE salient_schema SET version = 99");
    if (db.dialect() == Dialect::sqlite)  // PostgreSQL parses a statement when it runs it
      CHECK_THROWS_WITH_AS(db.prepare("SELEKT 1"), doctest::Contains("SQL error in \"SELEKT 1\""),
                           StoreError);
    CHECK_THROWS_WITH_AS(db.prepare("SELEKT 1").run(), doctest::Contains("SELEKT"), StoreError);
  }
  CHECK_THROWS_WITH_AS(Database(test_database(scratch)), doctest::Contains("newer than this salientd"),
                       StoreError);
}

TEST_CASE("one SQL for both backends: ? and ?N placeholders, quotes left alone, RETURNING, changes") {
  const salient::test::ScratchDir scratch("portable");
  Database db(test_database(scratch));
  auto q = db.prepare("SELECT ?2 || ?1, '?' || ?1, \"user\" FROM (SELECT 'x' AS \"user\") AS t");
  q.bind(1, std::string_view("a")).bind(2, std::string_view("b"));
  REQUIRE(q.step());
  CHECK(q.text(0) == "ba");
  CHECK(q.text(1) == "?a");
  CHECK(q.text(2) == "x");
  CHECK_FALSE(q.step());
  auto insert =
      db.prepare("INSERT INTO printers (id, config, updated_at) VALUES (?, ?, ?) RETURNING id, updated_at");
  insert.bind(1, std::string_view("p1")).bind(2, std::string_view("{}")).bind(3, 1.25);
  REQUIRE(insert.step());
  CHECK(insert.text(0) == "p1");
  CHECK(insert.real(1) == 1.25);
  insert.run();
  db.prepare("UPDATE printers SET updated_at = ? WHERE id = ?")
      .bind(1, std::int64_t{7})
      .bind(2, std::string_view("p1"))
      .run();
  CHECK(db.changes() == 1);
  // A statement runs again with its bindings, as a SQLite statement does after its reset.
  auto count = db.prepare("SELECT count(*), max(updated_at) FROM printers WHERE id = ?");
  count.bind(1, std::string_view("p1"));
  for (int i = 0; i < 2; ++i) {
    REQUIRE(count.step());
    CHECK(count.integer(0) == 1);
    CHECK(count.real(1) == 7);
    CHECK_FALSE(count.step());
  }
}

TEST_CASE("bytes of every value round-trip through a blob, a 64-bit integer intact, truth as 1 and 0") {
  const salient::test::ScratchDir scratch("blob");
  Database db(test_database(scratch));
  std::string bytes;
  for (int i = 0; i < 512; ++i) bytes += static_cast<char>(i & 0xff);
  auto q = db.prepare("SELECT ?, ?, 2.5, 1 = 1, 1 = 0");
  q.bind_blob(1, bytes).bind(2, std::int64_t{9007199254740993});  // 2^53 + 1: no double holds it
  REQUIRE(q.step());
  CHECK(q.blob(0) == bytes);
  CHECK(q.integer(1) == 9007199254740993);
  CHECK(q.integer(2) == 2);  // a real read as an integer is cut, as SQLite does
  CHECK(q.integer(3) == 1);  // a truth value is 1 or 0
  CHECK(q.integer(4) == 0);
}

TEST_CASE("store URLs choose the backend, and a bad one is refused with a reason") {
  CHECK(DatabaseUrl::parse("var/salient.db").dialect == Dialect::sqlite);
  CHECK(DatabaseUrl::parse("var/salient.db").target == "var/salient.db");
  CHECK(DatabaseUrl::parse("sqlite:/srv/s.db").target == "/srv/s.db");
  CHECK(DatabaseUrl::parse("sqlite:///srv/s.db").target == "/srv/s.db");
  const DatabaseUrl pg = DatabaseUrl::parse("postgresql://salient:secret@db.farm:5432/salient");
  CHECK(pg.dialect == Dialect::postgresql);
  CHECK(pg.target == "postgresql://salient:secret@db.farm:5432/salient");
  CHECK(pg.redacted() == "postgresql://salient:***@db.farm:5432/salient");
  CHECK(DatabaseUrl::parse("postgres://db/salient").dialect == Dialect::postgresql);
  CHECK_THROWS_WITH_AS(DatabaseUrl::parse("mysql://db/salient"),
                       doctest::Contains("unknown database URL scheme 'mysql'"), StoreError);
  CHECK_THROWS_AS(DatabaseUrl::parse(""), StoreError);
  CHECK_THROWS_AS(DatabaseUrl::parse("sqlite:"), StoreError);
  CHECK_THROWS_WITH_AS(Database(DatabaseUrl::parse("postgresql://127.0.0.1:1/nothing?connect_timeout=2")),
                       doctest::Contains("PostgreSQL: cannot connect"), StoreError);
}

TEST_CASE("a PostgreSQL connection that breaks fails its statement, then reconnects for the next") {
  if (!salient::test::on_postgresql()) {
    MESSAGE("PostgreSQL only: runs in server_store_pg_tests");
    return;
  }
  const salient::test::ScratchDir scratch("reconnect");
  Database db(test_database(scratch)), other(test_database(scratch));
  auto count = db.prepare("SELECT count(*) FROM jobs WHERE state = ?");
  count.bind(1, std::string_view("queued"));
  REQUIRE(count.step());  // prepared on this connection
  count.run();
  auto pid = db.prepare("SELECT pg_backend_pid()");
  REQUIRE(pid.step());
  const std::int64_t backend = pid.integer(0);
  pid.run();
  // Ended while a statement runs (an idle one is revived before its next: the test below).
  std::thread killer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    other.prepare("SELECT pg_terminate_backend(CAST(? AS INTEGER))").bind(1, backend).run();
  });
  auto slow = db.prepare("SELECT pg_sleep(10)");
  CHECK_THROWS_AS(slow.step(), StoreError);  // not run again: it might have been a write that committed
  killer.join();
  REQUIRE(count.step());  // a new session, where it is prepared again
  CHECK(count.integer(0) == 0);
}

// A migration written with SQLite's words alone would give PostgreSQL 32-bit integers (INTEGER),
// single-precision times (REAL) or a syntax error (AUTOINCREMENT, strftime): each must use the
// tokens of migrations.hpp, which this checks.
TEST_CASE("every migration is in each dialect's words: no token left, no SQLite-only word on PostgreSQL") {
  const std::regex sqlite_only(R"(\b(INTEGER|REAL|AUTOINCREMENT|strftime|PRAGMA)\b|\buser\b[^"])",
                               std::regex::icase);
  REQUIRE(migration_count() == Database::latest_schema_version());
  for (int i = 0; i < migration_count(); ++i) {
    for (Dialect d : {Dialect::sqlite, Dialect::postgresql})
      CHECK_MESSAGE(migration_sql(i, d).find('{') == std::string::npos, "migration ", i + 1);
    const std::string pg = migration_sql(i, Dialect::postgresql);
    std::smatch m;
    CHECK_MESSAGE(!std::regex_search(pg, m, sqlite_only), "migration ", i + 1, ": '", m.str(), "'");
  }
}

// Writers on separate connections (a thread each, as the daemon's) wait for each other inside a
// transaction: SQLite's BEGIN IMMEDIATE, PostgreSQL's advisory lock. Without it, two adds read
// the same MAX(position) and two workers start the same job.
TEST_CASE("concurrent writers: queue positions stay unique and each job starts once") {
  const salient::test::ScratchDir scratch("writers");
  Store store(scratch.path, test_database(scratch));
  JobStore setup(store.db());
  for (int i = 0; i < 40; ++i) setup.create("m.obj", std::to_string(i) + "m", "{}", "s", i);
  std::mutex mutex;
  std::vector<std::string> started;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      QueueStore queue(store.db());
      JobStore jobs(store.db());
      for (int i = 0; i < 15; ++i) {
        queue.add("p", "file", "f.gcode", 1);
        if (auto j = jobs.claim("n", 60, 2)) {
          std::lock_guard lock(mutex);
          started.push_back(j->id);
        }
      }
    });
  for (auto& t : threads) t.join();
  std::set<long long> positions;
  for (const QueueEntry& e : QueueStore(store.db()).list("p")) positions.insert(e.position);
  CHECK(positions.size() == 60);
  CHECK(*positions.rbegin() == 60);
  CHECK(started.size() == 40);
  CHECK(std::set<std::string>(started.begin(), started.end()).size() == 40);
}

TEST_CASE("PostgreSQL: a connection the server closed while idle (a restart) serves the next statement") {
  const salient::test::ScratchDir scratch("reconnect");
  Database a(test_database(scratch));
  if (a.dialect() != Dialect::postgresql) return;  // SQLite has no server to lose
  Database b(test_database(scratch));
  auto pid_of_a = a.prepare("SELECT pg_backend_pid()");
  REQUIRE(pid_of_a.step());
  const std::int64_t pid = pid_of_a.integer(0);
  pid_of_a.run();
  // What a restart does to every idle connection: its backend ends.
  b.prepare("SELECT pg_terminate_backend(CAST(? AS INTEGER))").bind(1, pid).run();
  auto gone = b.prepare("SELECT COUNT(*) FROM pg_stat_activity WHERE pid = ?");
  gone.bind(1, pid);
  for (int i = 0; i < 100; ++i) {
    REQUIRE(gone.step());
    const bool ended = gone.integer(0) == 0;
    gone.run();
    if (ended) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // The old code failed this statement (500 for each HTTP thread's next request) and reconnected after.
  auto q = a.prepare("SELECT 41 + 1");
  bool row = false;
  CHECK_NOTHROW(row = q.step());
  REQUIRE(row);
  CHECK(q.integer(0) == 42);
  q.run();
  // Inside a transaction the loss is not hidden: the transaction went with the old session.
  auto pid_again = a.prepare("SELECT pg_backend_pid()");
  REQUIRE(pid_again.step());
  const std::int64_t pid2 = pid_again.integer(0);
  pid_again.run();
  Database::Transaction t(a);
  b.prepare("SELECT pg_terminate_backend(CAST(? AS INTEGER))").bind(1, pid2).run();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  CHECK_THROWS_AS(a.prepare("SELECT 1").run(), StoreError);
}
