// Polygon types of our own (millimetres, XY plane); Clipper stays inside polygon_ops.cpp.
#pragma once

#include <vector>

namespace salient::core {

struct Point2 {
  double x = 0, y = 0;
  bool operator==(const Point2&) const = default;
};

// A closed ring; counter-clockwise encloses, clockwise is a hole.
using Polygon = std::vector<Point2>;
using Polygons = std::vector<Polygon>;

// An outer contour with the holes inside it.
struct ExPolygon {
  Polygon contour;
  Polygons holes;
};

// Shoelace area: positive for counter-clockwise rings.
double signed_area(const Polygon& ring);

// Whether p is inside the set (nonzero winding: holes, being clockwise, cut out).
bool contains(const Polygons& polygons, const Point2& p);
// Whether the segment a–b stays inside the set: its midpoint inside, no ring edge crossed.
bool segment_inside(const Polygons& polygons, const Point2& a, const Point2& b);

}  // namespace salient::core
