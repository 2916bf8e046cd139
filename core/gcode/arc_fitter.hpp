// Arc fitting: runs of a polyline's segments that lie on a circle become one G2/G3 move, as
// ArcWelder (Kelly 2020) and PrusaSlicer 2.6's arc fitting do, within a deviation bound.
#pragma once

#include <vector>

#include "core/geometry/polygon.hpp"

namespace salient::core {

// One move along a fitted path: straight to `to`, or an arc about `center` (counter-clockwise:
// G3, clockwise: G2), never more than half a turn, so that the end point rounded to G-code's
// precision cannot flip it to the other way round the circle.
struct PathMove {
  Point2 to;
  bool arc = false;
  bool ccw = false;
  Point2 center;
  double length = 0;  // mm along the move (the arc's, not its chord's)
};

// Moves from points[0] through points[1..]: greedily, the longest run of at least two segments
// whose vertices lie within `tolerance` (mm) of one circle, and whose chords stray no further
// than that from the arc, in one direction, becomes an arc; every other segment stays a line.
// Radii beyond max_radius (mm) stay lines: they are straight to within the tolerance anyway.
std::vector<PathMove> fit_arcs(const std::vector<Point2>& points, double tolerance, double max_radius = 1000);

}  // namespace salient::core
