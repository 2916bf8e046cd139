// simplify_polygon. A closed ring is split at two anchors that DP must keep: its first vertex and
// the vertex farthest from it; each of the two chains is then simplified as an open polyline
// (iteratively, so a ring of 10⁵ vertices does not recurse 10⁵ deep). Distances are to the
// segment, not to its line, so a spike past a chord's end is kept.
#include "core/geometry/polygon_simplify.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace salient::core {
namespace {

double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

// Marks in `keep` the vertices DP keeps between indices first and last (mod n), both kept.
void simplify_chain(const Polygon& ring, std::size_t first, std::size_t last, double tolerance,
                    std::vector<char>& keep) {
  const std::size_t n = ring.size();
  std::vector<std::pair<std::size_t, std::size_t>> stack{{0, (last + n - first) % n}};  // offsets from first
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    const Point2& a = ring[(first + lo) % n];
    const Point2& b = ring[(first + hi) % n];
    double worst = -1;
    std::size_t at = lo;
    for (std::size_t k = lo + 1; k < hi; ++k) {
      const double d = segment_distance(ring[(first + k) % n], a, b);
      if (d > worst) worst = d, at = k;
    }
    if (worst <= tolerance) continue;
    keep[(first + at) % n] = 1;
    stack.emplace_back(lo, at);
    stack.emplace_back(at, hi);
  }
}

}  // namespace

Polygon simplify_polygon(const Polygon& ring, double tolerance) {
  const std::size_t n = ring.size();
  if (n <= 3 || !(tolerance > 0)) return ring;
  std::size_t far = 0;
  double far_d = -1;
  for (std::size_t i = 1; i < n; ++i) {
    const double d = std::hypot(ring[i].x - ring[0].x, ring[i].y - ring[0].y);
    if (d > far_d) far_d = d, far = i;
  }
  std::vector<char> keep(n, 0);
  keep[0] = keep[far] = 1;
  simplify_chain(ring, 0, far, tolerance, keep);
  simplify_chain(ring, far, 0, tolerance, keep);
  Polygon out;
  for (std::size_t i = 0; i < n; ++i)
    if (keep[i]) out.push_back(ring[i]);
  if (out.size() >= 3) return out;
  // A sliver thinner than the tolerance: keep the vertex farthest from the anchors' chord, so
  // the ring stays a triangle rather than collapsing to a line.
  std::size_t third = 0;
  double third_d = -1;
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) continue;
    const double d = segment_distance(ring[i], ring[0], ring[far]);
    if (d > third_d) third_d = d, third = i;
  }
  keep[third] = 1;
  out.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (keep[i]) out.push_back(ring[i]);
  return out;
}

Polygons simplify_polygons(const Polygons& rings, double tolerance) {
  Polygons out;
  out.reserve(rings.size());
  for (const Polygon& ring : rings) out.push_back(simplify_polygon(ring, tolerance));
  return out;
}

}  // namespace salient::core
