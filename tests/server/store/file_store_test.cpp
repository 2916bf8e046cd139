#include "server/store/file_store.hpp"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "server/store/database_blobs.hpp"
#include "server/store/sha256.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

namespace fs = std::filesystem;
using namespace salient::server;

TEST_CASE("files are stored under their digest, once, and read back intact") {
  const salient::test::ScratchDir scratch("files");
  const fs::path& root = scratch.path;
  FileStore store(root);
  const std::string bytes = "solid cube\nendsolid cube\n";
  const std::string d = store.put(bytes);
  CHECK(d == sha256_hex(bytes));
  CHECK(store.contains(d));
  CHECK(store.read(d) == bytes);
  CHECK(store.path_of(d) == root / "objects" / d.substr(0, 2) / d.substr(2));
  CHECK(store.put(bytes) == d);  // same bytes: same file
  CHECK(std::distance(fs::directory_iterator(root / "tmp"), fs::directory_iterator{}) == 0);
  store.remove(d);
  CHECK_FALSE(store.contains(d));
}

TEST_CASE("digests from outside never become paths, and interrupted writes are cleared") {
  const salient::test::ScratchDir scratch("bad");
  const fs::path& root = scratch.path;
  {
    FileStore store(root);
    std::ofstream(root / "tmp" / "half-written") << "partial";
  }
  FileStore store(root);  // a restart
  CHECK(fs::is_empty(root / "tmp"));
  CHECK_FALSE(store.contains("../../etc/passwd"));
  CHECK_THROWS_AS(store.path_of("../../etc/passwd"), StoreError);
  CHECK_THROWS_AS(store.read(std::string(64, 'A')), StoreError);  // upper case is not ours
  CHECK_THROWS_AS(store.read(std::string(64, 'a')), StoreError);  // well formed, absent
}

namespace {

fs::path cached(const salient::test::ScratchDir& node, const std::string& d) {
  return node.path / "files" / "objects" / d.substr(0, 2) / d.substr(2);
}

long long chunks(Store& store, const std::string& d) {
  auto q = store.db().prepare("SELECT count(*) FROM blobs WHERE digest = ?");
  q.bind(1, std::string_view(d));
  q.step();
  const long long n = q.integer(0);
  q.run();
  return n;
}

}  // namespace

TEST_CASE("on PostgreSQL files live in the database: another node fetches them in chunks, checked") {
  if (!salient::test::on_postgresql()) {
    MESSAGE("PostgreSQL only: runs in server_store_pg_tests");
    return;
  }
  const salient::test::ScratchDir a("node-a"), b("node-b"), c("node-c");
  const DatabaseUrl url = salient::test::test_database(a);
  Store node_a(a.path, url), node_b(b.path, url);
  std::string big(2 * DatabaseBlobs::chunk_bytes + 12345, '\0');
  std::mt19937 rng(7);
  for (char& ch : big) ch = static_cast<char>(rng());
  const std::string d = node_a.files().put(big);
  const std::string empty = node_a.files().put("");
  CHECK(chunks(node_a, d) == 3);
  CHECK(chunks(node_a, empty) == 1);  // its chunk 0 says it is there
  CHECK_FALSE(fs::exists(cached(b, d)));
  CHECK(node_b.files().contains(d));
  CHECK(node_b.files().read(d) == big);
  CHECK(fs::exists(cached(b, d)));  // cached: files never change
  CHECK(node_b.files().read(empty).empty());
  CHECK(node_b.files().put(big) == d);
  CHECK(chunks(node_b, d) == 3);  // stored once

  // A chunk changed behind our back: the node that fetches it refuses the bytes, caches nothing.
  node_a.db()
      .prepare("UPDATE blobs SET data = ? WHERE digest = ? AND chunk_no = 1")
      .bind_blob(1, "x")
      .bind(2, std::string_view(d))
      .run();
  Store node_c(c.path, url);
  CHECK_THROWS_WITH_AS(node_c.files().read(d), doctest::Contains("other bytes"), StoreError);
  CHECK_FALSE(fs::exists(cached(c, d)));
  CHECK(fs::is_empty(c.path / "files" / "tmp"));

  node_a.files().remove(d);
  CHECK(chunks(node_a, d) == 0);
  CHECK_FALSE(node_c.files().contains(d));
  CHECK_THROWS_AS(node_c.files().read(d), StoreError);
}

TEST_CASE("a directory the nodes share keeps the files instead of the database") {
  const salient::test::ScratchDir a("shared-a"), shared("shared-files");
  Store store(a.path, salient::test::test_database(a), shared.path);
  const std::string d = store.files().put("G28\n");
  CHECK(fs::exists(shared.path / "objects" / d.substr(0, 2) / d.substr(2)));
  CHECK_FALSE(fs::exists(cached(a, d)));
  if (store.db().dialect() == Dialect::postgresql) CHECK(chunks(store, d) == 0);
}
