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

// An open polyline (e.g. an infill line).
using Polyline = std::vector<Point2>;
using Polylines = std::vector<Polyline>;

Polygons union_of(const Polygons& polygons);
Polygons intersection_of(const Polygons& a, const Polygons& b);
Polygons difference_of(const Polygons& a, const Polygons& b);
std::vector<ExPolygon> union_ex(const Polygons& polygons);
std::vector<ExPolygon> difference_ex(const Polygons& a, const Polygons& b);

// Grows (delta > 0) or shrinks (delta < 0) the area by |delta| mm, mitred corners (limit 3).
Polygons offset(const Polygons& polygons, double delta);
// The parts of open `lines` inside `region` (nonzero rule).
Polylines clip_lines(const Polylines& lines, const Polygons& region);
// Rings of an ExPolygon set, holes included, for the functions above.
Polygons to_polygons(const std::vector<ExPolygon>& expolygons);

}  // namespace salient::core
