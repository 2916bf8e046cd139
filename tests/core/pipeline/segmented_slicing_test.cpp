// The time SegOpt decides by (region_print_seconds): regions printed side by side are one print,
// so the minimum layer time is charged once per printed height of the whole, not per region.
#include "core/pipeline/segmented_slicing.hpp"

#include <doctest/doctest.h>

#include "core/gcode/gcode_writer.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/segment/cut_plane.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

// A region of the whole height on one side of x = cx, in layers of `cells` grid cells.
PlanRegion half(const ZProfile& p, int side, double cx, int cells) {
  PlanRegion r;
  r.side = side;
  r.last_cell = p.cells();
  r.clip = side == 0 ? rectangle({0, 0}, {cx, 300}) : rectangle({cx, 0}, {300, 300});
  for (int b = 0; b <= p.cells(); b += cells) r.plan.boundaries.push_back(b);
  return r;
}

}  // namespace

TEST_CASE("two parts side by side cool together: the minimum layer time is charged per printed height") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  // A small box, 20 × 10 × 6 mm: every layer of it, let alone of half of it, prints in well under
  // the minimum layer time at full speed, so each printed height is slowed to that time.
  Mesh box = salient::test::box(20, 10, 6);
  const Vec3 at{printer.bed_center_x() - 10, printer.bed_center_y() - 5, 0};
  for (Vec3& p : box.positions) p = p + at;
  const std::vector<float> saliency(box.vertex_count(), 1.0f);
  const ZProfile profile = ZProfile::build(box, saliency, {printer.min_layer, printer.max_layer, 0.01});
  const double cx = printer.bed_center_x();
  const RegionSliceSettings settings;
  const auto seconds = [&](const std::vector<PlanRegion>& regions) {
    return region_print_seconds(box, profile, regions, settings, printer);
  };
  // The whole section in 0.1 mm layers (60 printed heights); the left half in 0.1 mm layers and the
  // right half in 0.1 or in 0.3 mm ones, whose tops are every third of the left's.
  PlanRegion whole = half(profile, -1, cx, 10);
  whole.clip.clear();
  const double whole_fine = seconds({whole});
  const double fine_fine = seconds({half(profile, 0, cx, 10), half(profile, 1, cx, 10)});
  const double fine_coarse = seconds({half(profile, 0, cx, 10), half(profile, 1, cx, 30)});
  const double min_layer_time = GcodeSettings{}.min_layer_time;
  INFO("whole ", whole_fine, " s, fine|fine ", fine_fine, " s, fine|coarse ", fine_coarse, " s");
  CHECK(fine_coarse >= 60 * min_layer_time);  // each of the 60 printed heights takes its time
  // Two halves at the same heights cool as one layer (charged per region: 60 × 8 s more).
  CHECK(fine_fine < whole_fine + 0.25 * 60 * min_layer_time);
  // While the right half's coarse layer waits for its next top, it cools as the left half prints:
  // its 20 layers add no cooling time of their own (charged per region: 20 × 8 s more).
  CHECK(fine_coarse < fine_fine + 0.25 * 20 * min_layer_time);
}
