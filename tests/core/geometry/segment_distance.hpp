// The distance from a point to a segment, for the tests that bound a path's deviation.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/geometry/polygon.hpp"

namespace salient::test {

inline double segment_distance(const core::Point2& p, const core::Point2& a, const core::Point2& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0;
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

}  // namespace salient::test
