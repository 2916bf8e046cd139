// Polygon measures.
#include "core/geometry/polygon.hpp"

namespace salient::core {

double signed_area(const Polygon& ring) {
  double twice = 0;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Point2& a = ring[i];
    const Point2& b = ring[(i + 1) % n];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * twice;
}

namespace {

double orient(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool proper_cross(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  return ((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0;
}

}  // namespace

bool contains(const Polygons& polygons, const Point2& p) {
  int winding = 0;
  for (const Polygon& ring : polygons)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      const Point2& a = ring[i];
      const Point2& b = ring[(i + 1) % n];
      if (a.y <= p.y) {
        if (b.y > p.y && orient(a, b, p) > 0) ++winding;
      } else if (b.y <= p.y && orient(a, b, p) < 0) {
        --winding;
      }
    }
  return winding != 0;
}

bool segment_inside(const Polygons& polygons, const Point2& a, const Point2& b) {
  if (!contains(polygons, {(a.x + b.x) / 2, (a.y + b.y) / 2})) return false;
  for (const Polygon& ring : polygons)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i)
      if (proper_cross(a, b, ring[i], ring[(i + 1) % n])) return false;
  return true;
}

}  // namespace salient::core
