// CutPlane: a vertical plane that divides a model into two parts (paper §5: only vertical cuts,
// so the parts' layers never overlap or leave voids along the cut).
#pragma once

#include "core/geometry/polygon.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

// Points p with nx·p.x + ny·p.y < offset are on side 0, the others on side 1; (nx, ny) is a unit
// vector in the XY plane.
struct CutPlane {
  double nx = 1, ny = 0, offset = 0;

  double distance(const Vec3& p) const { return nx * p.x + ny * p.y - offset; }
  double distance(const Point2& p) const { return nx * p.x + ny * p.y - offset; }
  int side(const Vec3& p) const { return distance(p) < 0 ? 0 : 1; }
};

// The part of a convex polygon (counter-clockwise) on `side` of the plane, counter-clockwise: the
// clip polygon a part's toolpaths are cut to. Empty if the plane leaves nothing on that side.
Polygon half_plane(const CutPlane& plane, int side, const Polygon& convex);

// The rectangle [min, max], counter-clockwise.
Polygon rectangle(const Point2& min, const Point2& max);

}  // namespace salient::core
