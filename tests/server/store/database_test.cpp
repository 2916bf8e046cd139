#include "server/store/database.hpp"

#include <doctest/doctest.h>

#include <filesystem>

#include "tests/support/scratch_dir.hpp"

namespace fs = std::filesystem;
using namespace salient::server;

TEST_CASE("a new database is migrated to the latest schema, in WAL mode") {
  const salient::test::ScratchDir scratch("new");
  const fs::path& dir = scratch.path;
  Database db(dir / "salient.db");
  CHECK(db.schema_version() == Database::latest_schema_version());
  auto mode = db.prepare("PRAGMA journal_mode");
  REQUIRE(mode.step());
  CHECK(mode.text(0) == "wal");
  for (const char* table : {"jobs", "prints", "printers", "api_keys"}) {
    auto q = db.prepare("SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = ?");
    q.bind(1, std::string_view(table));
    REQUIRE(q.step());
    CHECK(q.integer(0) == 1);
  }
}

TEST_CASE("rows survive reopening, constraints hold, transactions roll back unless committed") {
  const salient::test::ScratchDir scratch("rows");
  const fs::path& dir = scratch.path;
  {
    Database db(dir / "salient.db");
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
    {
      Database::Transaction t(db);
      db.exec("UPDATE jobs SET state = 'running'");
    }  // no commit: rolled back
  }
  Database again(dir / "salient.db");
  CHECK(again.schema_version() == Database::latest_schema_version());
  auto q = again.prepare("SELECT id, state, filename, created_at, error FROM jobs");
  REQUIRE(q.step());
  CHECK(q.text(0) == "j1");
  CHECK(q.text(1) == "queued");
  CHECK(q.real(3) == 1.5);
  CHECK(q.null(4));
  CHECK_FALSE(q.step());
}

TEST_CASE("a database from a newer salientd is refused with a reason, and bad SQL names itself") {
  const salient::test::ScratchDir scratch("newer");
  const fs::path& dir = scratch.path;
  {
    Database db(dir / "salient.db");
    db.exec("PRAGMA user_version = 99");
    CHECK_THROWS_WITH_AS(db.prepare("SELEKT 1"), doctest::Contains("SQL error in \"SELEKT 1\""), StoreError);
  }
  CHECK_THROWS_WITH_AS(Database(dir / "salient.db"), doctest::Contains("newer than this salientd"),
                       StoreError);
}
