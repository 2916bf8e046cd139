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

}  // namespace salient::core
