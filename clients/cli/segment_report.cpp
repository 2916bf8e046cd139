#include "clients/cli/segment_report.hpp"

#include <cstdio>
#include <string>

namespace salient::cli {
namespace {

std::string part_name(const core::PlanRegion& r) {
  if (r.side < 0) return "whole";
  std::string name = "part " + std::to_string(r.side);
  for (int s : r.sub) name += "." + std::to_string(s);
  return name;
}

}  // namespace

void print_segmentation(const core::SegOptResult& r, const core::ZProfile& whole) {
  std::printf("segmentation: %s\n", r.note.c_str());
  if (r.seam)
    std::printf(
        "  plane     %.3f x + %.3f y = %.2f: seam %.1f mm, mean Q + 0.3 S %.3f, D %.3f, f(C) %.3f, smaller "
        "part %.0f%%\n",
        r.seam->plane.nx, r.seam->plane.ny, r.seam->plane.offset, r.seam->length, r.seam->seam_mean,
        r.seam->difference, r.seam->cost, 100 * r.seam->share);
  std::printf("  time      whole %.1f min", r.whole_seconds / 60);
  if (r.parts_seconds > 0)
    std::printf(", parts %.1f min (%.0f%%)", r.parts_seconds / 60, 100 * r.parts_seconds / r.whole_seconds);
  std::printf(", result %.1f min\n", r.seconds / 60);
  for (const core::PlanRegion& region : r.regions)
    std::printf("  region    %-10s z %7.2f..%7.2f mm  %4d layers  E %.6g (epsilon %.6g)\n",
                part_name(region).c_str(), whole.z(region.first_cell), whole.z(region.last_cell),
                region.layers(), region.error, region.epsilon);
}

}  // namespace salient::cli
