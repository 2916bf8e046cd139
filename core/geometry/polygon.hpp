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

}  // namespace salient::core
