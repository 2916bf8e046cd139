// One source for each figure a slice reports (issue 32 item 3): the print time the result, the
// job and the text say is the G-code's estimate, also in the times against uniform layers; and
// "finest" is the layer count the fine planner's own slice has, the fixed first layer counted.
#include <doctest/doctest.h>

#include "core/pipeline/slice_pipeline.hpp"
#include "core/printer/printer_profile.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

SliceResult slice_spot(PlannerKind planner, bool support) {
  SliceSettings settings;
  settings.plan.mesh.model = salient::test::model_path("spot.obj");
  settings.plan.mesh.up = "y";
  settings.plan.mesh.height = 20;
  settings.plan.planner = planner;
  settings.support = support;
  settings.toolpaths.infill_density = 0.1;
  return slice_model(settings, *builtin_printer("generic-i3"), {});
}

}  // namespace

TEST_CASE("a slice's print time is one figure: the G-code's estimate, with and without support") {
  for (const bool support : {false, true}) {
    CAPTURE(support);
    const SliceResult r = slice_spot(PlannerKind::exact, support);
    REQUIRE(r.plan.times);
    CHECK(r.print_seconds > 0);
    CHECK(r.plan.times->plan_seconds == doctest::Approx(r.print_seconds).epsilon(1e-9));
    // The uniform prints beside it keep their order: finest slowest, the usual 0.2 mm quickest.
    CHECK(r.plan.times->fine_seconds > r.plan.times->plan_seconds);
    CHECK(r.plan.times->default_seconds < r.plan.times->plan_seconds);
  }
}

TEST_CASE("'finest' is the fine planner's own layer count, the fixed first layer counted") {
  const SliceResult exact = slice_spot(PlannerKind::exact, false);
  const SliceResult fine = slice_spot(PlannerKind::fine, false);
  CHECK(fine.layers == exact.finest_layers);
  CHECK(exact.plan.fine_layers == exact.finest_layers);
  CHECK(exact.layers < exact.finest_layers);
}
