// PointGrid: a uniform grid over points for fixed-radius neighbour queries (never all-pairs).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh/vec3.hpp"

namespace salient::core {

class PointGrid {
 public:
  // `cell` should be about the query radius.
  PointGrid(std::span<const Vec3> points, double cell);

  // Calls f(index, squared distance) for every point within `radius` of `q`.
  template <typename F>
  void for_each_within(const Vec3& q, double radius, F&& f) const {
    const double r2 = radius * radius;
    const int x0 = coord(q.x - radius, 0), x1 = coord(q.x + radius, 0);
    const int y0 = coord(q.y - radius, 1), y1 = coord(q.y + radius, 1);
    const int z0 = coord(q.z - radius, 2), z1 = coord(q.z + radius, 2);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const std::size_t c = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
          for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
            const std::uint32_t i = order_[k];
            const Vec3 d = points_[i] - q;
            const double d2 = dot(d, d);
            if (d2 <= r2) f(i, d2);
          }
        }
  }

 private:
  int coord(double v, int axis) const {
    const double t = std::floor((v - origin_[axis]) * inv_);
    return static_cast<int>(std::clamp(t, 0.0, static_cast<double>(dims_[axis] - 1)));
  }

  std::span<const Vec3> points_;
  Vec3 origin_;
  double inv_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<std::uint32_t> start_, order_;
};

}  // namespace salient::core
