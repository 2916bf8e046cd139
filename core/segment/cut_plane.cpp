#include "core/segment/cut_plane.hpp"

namespace salient::core {

Polygon rectangle(const Point2& min, const Point2& max) {
  return {{min.x, min.y}, {max.x, min.y}, {max.x, max.y}, {min.x, max.y}};
}

Polygon half_plane(const CutPlane& plane, int side, const Polygon& box) {
  // Sutherland–Hodgman against one half-plane: keep where the signed distance is ≤ 0.
  const auto d = [&](const Point2& p) { return side == 0 ? plane.distance(p) : -plane.distance(p); };
  Polygon out;
  for (std::size_t i = 0; i < box.size(); ++i) {
    const Point2& a = box[i];
    const Point2& b = box[(i + 1) % box.size()];
    const double da = d(a), db = d(b);
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      const double t = da / (da - db);
      out.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
    }
  }
  if (out.size() < 3) out.clear();
  return out;
}

}  // namespace salient::core
