// rectilinear_infill: rotate the region so the lines run along x, cut it with horizontal lines,
// rotate back; then alternate directions (a zig-zag without the connecting moves).
#include "core/toolpath/infill_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace salient::core {
namespace {

Point2 rotate(const Point2& p, double c, double s) {
  return {c * p.x - s * p.y, s * p.x + c * p.y};
}

}  // namespace

Polylines rectilinear_infill(const Polygons& region, double spacing, double angle) {
  if (region.empty() || !(spacing > 0)) return {};
  const double c = std::cos(-angle), s = std::sin(-angle);
  Polygons turned = region;
  double x0 = std::numeric_limits<double>::max(), x1 = -x0, y0 = x0, y1 = -x0;
  for (Polygon& ring : turned)
    for (Point2& p : ring) {
      p = rotate(p, c, s);
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
    }
  Polylines lines;
  for (double y = std::ceil(y0 / spacing) * spacing; y <= y1; y += spacing)
    lines.push_back({{x0 - 1, y}, {x1 + 1, y}});
  Polylines clipped = clip_lines(lines, turned);
  // Sort by scanline, then alternate direction so each line starts where the last ended.
  for (Polyline& l : clipped)
    if (l.front().x > l.back().x) std::reverse(l.begin(), l.end());
  std::sort(clipped.begin(), clipped.end(), [](const Polyline& a, const Polyline& b) {
    if (std::fabs(a.front().y - b.front().y) > 1e-9) return a.front().y < b.front().y;
    return a.front().x < b.front().x;
  });
  bool flip = false;
  double last_y = std::numeric_limits<double>::quiet_NaN();
  for (Polyline& l : clipped) {
    if (!(std::fabs(l.front().y - last_y) < 1e-9)) flip = !flip, last_y = l.front().y;
    if (flip) std::reverse(l.begin(), l.end());
    for (Point2& p : l) p = rotate(p, std::cos(angle), std::sin(angle));
  }
  return clipped;
}

}  // namespace salient::core
