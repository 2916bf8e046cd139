// Boolean operations and measures on polygon sets (nonzero fill rule), as free functions over
// our own types (after PrusaSlicer's ClipperUtils). Coordinates are snapped to 10 nm.
#pragma once

#include "core/geometry/polygon.hpp"

namespace salient::core {

// Area covered by `polygons` (their union under the nonzero rule), mm².
double covered_area(const Polygons& polygons);
// Area covered by both sets, mm².
double intersection_area(const Polygons& a, const Polygons& b);
// Area covered by exactly one of the sets: |A| + |B| − 2|A ∩ B|, mm².
double xor_area(const Polygons& a, const Polygons& b);

Polygons union_of(const Polygons& polygons);
Polygons intersection_of(const Polygons& a, const Polygons& b);
Polygons difference_of(const Polygons& a, const Polygons& b);
std::vector<ExPolygon> union_ex(const Polygons& polygons);

}  // namespace salient::core
