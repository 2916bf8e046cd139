#include "server/store/print_store.hpp"

#include <doctest/doctest.h>

#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

using namespace salient::server;

TEST_CASE("prints: progress as it goes, finished, and those a crash left become interrupted") {
  salient::test::ScratchDir dir("print-store");
  Store store(dir.path, salient::test::test_database(dir));
  PrintStore prints(store.db());
  const PrintRecord a = prints.create("sim", std::nullopt, "abc", "a.gcode", 1000, 10.0);
  CHECK(a.state == PrintState::printing);
  CHECK(a.total == 1000);
  prints.set_progress(a.id, PrintState::paused, 400);
  CHECK(prints.get(a.id)->confirmed == 400);
  CHECK(prints.get(a.id)->state == PrintState::paused);
  prints.finish(a.id, PrintState::finished, 1000, std::nullopt, 20.0);
  prints.set_progress(a.id, PrintState::printing, 3);  // a late update cannot reopen a finished print
  CHECK(prints.get(a.id)->state == PrintState::finished);
  CHECK(prints.get(a.id)->confirmed == 1000);
  const PrintRecord b = prints.create("sim", std::nullopt, "def", "b.gcode", 500, 30.0);
  prints.set_progress(b.id, PrintState::printing, 123);
  prints.create("other", std::nullopt, "def", "b.gcode", 500, 31.0);
  CHECK(prints.latest("sim")->id == b.id);
  CHECK(prints.list("sim", 10).size() == 2);
  CHECK(prints.mark_interrupted(40.0) == 2);
  const auto after = prints.get(b.id);
  CHECK(after->state == PrintState::interrupted);
  CHECK(after->confirmed == 123);
  CHECK(after->finished_at == 40.0);
  CHECK(prints.mark_interrupted(41.0) == 0);
  CHECK(!prints.get(9999));
}

TEST_CASE("files: stored by name, replaced by a new upload of the same name, removed") {
  salient::test::ScratchDir dir("print-files");
  Store store(dir.path, salient::test::test_database(dir));
  PrintStore prints(store.db());
  prints.put_file("a.gcode", "d1", 10, 1.0);
  prints.put_file("b.gcode", "d2", 20, 2.0);
  prints.put_file("a.gcode", "d3", 30, 3.0);
  CHECK(prints.file("a.gcode")->digest == "d3");
  CHECK(prints.files().size() == 2);
  CHECK(prints.files().front().name == "a.gcode");  // newest first
  CHECK(prints.remove_file("b.gcode"));
  CHECK(!prints.remove_file("b.gcode"));
  CHECK(!prints.file("b.gcode"));
}
