#include "server/store/file_store.hpp"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "server/store/sha256.hpp"
#include "tests/support/scratch_dir.hpp"

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
