// The database a store test runs on. SQLite in the test's scratch directory by default; in the
// PostgreSQL build (server_store_pg_tests, compiled with SALIENT_TEST_PG_DIR) or with
// SALIENT_TEST_BACKEND=postgresql, a fresh database of its own in the cluster pg_cluster.sh
// started, found through SALIENT_TEST_PG_URL (postgresql://USER@HOST:PORT) or the file
// $SALIENT_TEST_PG_DIR/url. No cluster there: the test exits 77 (skipped) with the reason.
#pragma once

#include "server/store/database_url.hpp"
#include "tests/support/scratch_dir.hpp"

namespace salient::test {

bool on_postgresql();
// The same scratch directory gives the same database (a test that reopens it finds its rows).
server::DatabaseUrl test_database(const ScratchDir& scratch);

}  // namespace salient::test
