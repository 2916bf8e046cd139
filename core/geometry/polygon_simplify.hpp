// Douglas–Peucker simplification of closed rings within a bounded deviation (Douglas & Peucker
// 1973; PrusaSlicer's gcode_resolution plays the tolerance's part).
#pragma once

#include "core/geometry/polygon.hpp"

namespace salient::core {

// The ring with the fewest of its own vertices that DP keeps: every removed vertex, and so every
// point of the original ring, lies within `tolerance` (mm) of the result, and the result's
// vertices are the original's (Hausdorff distance ≤ tolerance). A ring of three or more vertices
// keeps at least three (never collapsed or dropped), so a small hole or pin keeps its shape and
// stays closed. tolerance ≤ 0 returns the ring unchanged.
Polygon simplify_polygon(const Polygon& ring, double tolerance);
Polygons simplify_polygons(const Polygons& rings, double tolerance);

}  // namespace salient::core
