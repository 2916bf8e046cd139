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
  prints.set_progress(a.id, PrintState::paused, 400, {12.5, 0});
  CHECK(prints.get(a.id)->confirmed == 400);
  CHECK(prints.get(a.id)->state == PrintState::paused);
  CHECK(prints.get(a.id)->filament_mm == 12.5);
  prints.finish(a.id, PrintState::finished, 1000, std::nullopt, 20.0, {30, 2});
  prints.set_progress(a.id, PrintState::printing, 3, {1, 0});  // a late update cannot reopen a finished print
  CHECK(prints.get(a.id)->state == PrintState::finished);
  CHECK(prints.get(a.id)->confirmed == 1000);
  CHECK(prints.get(a.id)->filament_mm == 30);
  CHECK(prints.get(a.id)->paused_seconds == 2);
  const PrintRecord b = prints.create("sim", std::nullopt, "def", "b.gcode", 500, 30.0);
  prints.set_progress(b.id, PrintState::printing, 123, {4, 0});
  prints.create("other", std::nullopt, "def", "b.gcode", 500, 31.0);
  CHECK(prints.latest("sim")->id == b.id);
  CHECK(prints.list("sim", 10).size() == 2);
  CHECK(prints.mark_interrupted(40.0) == 2);
  const auto after = prints.get(b.id);
  CHECK(after->state == PrintState::interrupted);
  CHECK(after->confirmed == 123);
  CHECK(after->finished_at == 40.0);
  CHECK(after->filament_mm == 4);  // what it used until the crash stays
  CHECK(prints.mark_interrupted(41.0) == 0);
  CHECK(!prints.get(9999));
}

TEST_CASE("totals: ended prints only, per printer or all, pauses out of the printing time") {
  salient::test::ScratchDir dir("print-totals");
  Store store(dir.path);
  PrintStore prints(store.db());
  CHECK(prints.totals("").prints == 0);
  CHECK(prints.totals("").longest_seconds == 0);
  const auto a = prints.create("sim", std::nullopt, "a", "a.gcode", 10, 100);
  prints.finish(a.id, PrintState::finished, 10, std::nullopt, 160, {100, 20});
  const auto b = prints.create("sim", std::nullopt, "b", "b.gcode", 10, 200);
  prints.finish(b.id, PrintState::cancelled, 4, std::nullopt, 230, {40, 0});
  const auto c = prints.create("other", std::nullopt, "c", "c.gcode", 10, 300);
  prints.finish(c.id, PrintState::failed, 2, std::string("thermal runaway"), 310, {5, 0});
  const auto d = prints.create("sim", std::nullopt, "d", "d.gcode", 10, 400);  // still printing
  prints.set_progress(d.id, PrintState::printing, 5, {50, 0});
  const auto e = prints.create("sim", std::nullopt, "e", "e.gcode", 10, 500);  // a clock set back
  prints.finish(e.id, PrintState::interrupted, 0, std::nullopt, 490, {0, 0});
  const PrintTotals sim = prints.totals("sim");
  CHECK(sim.prints == 3);
  CHECK(sim.finished == 1);
  CHECK(sim.cancelled == 1);
  CHECK(sim.interrupted == 1);
  CHECK(sim.failed == 0);
  CHECK(sim.total_seconds == doctest::Approx(60 + 30));
  CHECK(sim.print_seconds == doctest::Approx(40 + 30));
  CHECK(sim.filament_mm == doctest::Approx(140));
  CHECK(sim.longest_seconds == doctest::Approx(60));
  CHECK(sim.longest_print_seconds == doctest::Approx(40));
  const PrintTotals all = prints.totals("");
  CHECK(all.prints == 4);
  CHECK(all.failed == 1);
  CHECK(all.filament_mm == doctest::Approx(145));
  CHECK(prints.totals("nobody").prints == 0);
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
