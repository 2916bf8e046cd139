// Folders of uploaded files and the settings table: paths moved and copied with what is under
// them (and nothing that only shares a prefix), removed recursively, and settings kept.
#include <doctest/doctest.h>

#include <algorithm>

#include "server/store/print_store.hpp"
#include "server/store/queue_store.hpp"
#include "server/store/settings_store.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;

namespace {
std::vector<std::string> names(PrintStore& s) {
  std::vector<std::string> out;
  for (const StoredFile& f : s.files()) out.push_back(f.name);
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

TEST_CASE("folders: ancestors made, move and copy take the subtree only, remove is recursive") {
  salient::test::ScratchDir dir("print-store-folders");
  Store store(dir.path, salient::test::test_database(dir));
  PrintStore files(store.db());
  files.put_folder("a/b/c", 1);
  CHECK(files.folders() == std::vector<std::string>{"a", "a/b", "a/b/c"});
  files.put_folder("a/b", 2);  // exists: nothing changes
  CHECK(files.folders().size() == 3);
  // "a_x" and "a%" share a prefix with "a" (and '%', '_' are LIKE's wildcards): never touched.
  for (const char* n : {"a/b/c/one.gcode", "a/two.gcode", "a_x.gcode", "a%/three.gcode"})
    files.put_file(n, "d", 10, 3);
  files.put_folder("a%", 3);
  files.move_folder("a", "z/a");
  CHECK(names(files) ==
        std::vector<std::string>{"a%/three.gcode", "a_x.gcode", "z/a/b/c/one.gcode", "z/a/two.gcode"});
  CHECK(files.folder_exists("z/a/b/c"));
  CHECK_FALSE(files.folder_exists("a/b"));
  files.copy_folder("z/a", "copy", 4);
  CHECK(files.file("copy/b/c/one.gcode").has_value());
  CHECK(files.file("z/a/b/c/one.gcode").has_value());
  CHECK(files.folder_exists("copy/b/c"));
  files.copy_file("a_x.gcode", "copy/x.gcode", 5);
  CHECK(files.file("copy/x.gcode")->digest == "d");
  files.move_file("copy/x.gcode", "y.gcode");
  CHECK_FALSE(files.file("copy/x.gcode").has_value());
  const auto removed = files.remove_folder("copy");
  CHECK(removed.size() == 2);
  CHECK_FALSE(files.folder_exists("copy"));
  CHECK_FALSE(files.folder_exists("copy/b/c"));
  CHECK(names(files) == std::vector<std::string>{"a%/three.gcode", "a_x.gcode", "y.gcode",
                                                 "z/a/b/c/one.gcode", "z/a/two.gcode"});
}

TEST_CASE("folders: queued prints follow their files when they move") {
  salient::test::ScratchDir dir("print-store-queue-move");
  Store store(dir.path, salient::test::test_database(dir));
  PrintStore files(store.db());
  QueueStore queue(store.db());
  files.put_file("f/a.gcode", "d", 1, 1);
  files.put_file("b.gcode", "d", 1, 1);
  queue.add("sim", "file", "f/a.gcode", 1);
  queue.add("sim", "file", "b.gcode", 2);
  queue.add("sim", "job", "b.gcode", 3);  // a job id that happens to look like the file: untouched
  files.move_folder("f", "g/f");
  files.move_file("b.gcode", "g/b.gcode");
  const auto entries = queue.list("sim");
  REQUIRE(entries.size() == 3);
  CHECK(entries[0].ref == "g/f/a.gcode");
  CHECK(entries[1].ref == "g/b.gcode");
  CHECK(entries[2].ref == "b.gcode");
}

TEST_CASE("settings: put replaces, get reads back after reopening") {
  salient::test::ScratchDir dir("settings-store");
  {
    Store store(dir.path, salient::test::test_database(dir));
    SettingsStore s(store.db());
    CHECK_FALSE(s.get("octoprint").has_value());
    s.put("octoprint", R"({"a":1})", 1);
    s.put("octoprint", R"({"a":2})", 2);
  }
  Store again(dir.path, salient::test::test_database(dir));
  CHECK(SettingsStore(again.db()).get("octoprint") == R"({"a":2})");
}
