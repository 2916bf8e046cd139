// PointGrid: counting sort of the points into cells (at most ~4 cells per point overall).
#include "core/geometry/point_grid.hpp"

#include <algorithm>
#include <limits>

namespace salient::core {

PointGrid::PointGrid(std::span<const Vec3> points, double cell) : points_(points) {
  Vec3 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
          std::numeric_limits<double>::max()};
  Vec3 hi{-lo.x, -lo.y, -lo.z};
  for (const Vec3& p : points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  if (points.empty()) lo = hi = {};
  origin_ = lo;
  // Never more cells than a few per point, whatever radius is asked.
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-12});
  const double min_cell = extent / std::max(1.0, std::cbrt(4.0 * static_cast<double>(points.size())));
  cell = std::max(cell, min_cell);
  inv_ = 1.0 / cell;
  for (int a = 0; a < 3; ++a)
    dims_[a] = std::max(1, static_cast<int>(std::floor((hi[a] - lo[a]) * inv_)) + 1);
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  start_.assign(cells + 1, 0);
  std::vector<std::uint32_t> cell_of(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    cell_of[i] = static_cast<std::uint32_t>(
        (static_cast<std::size_t>(coord(p.z, 2)) * dims_[1] + coord(p.y, 1)) * dims_[0] + coord(p.x, 0));
    ++start_[cell_of[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  order_.resize(points.size());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) order_[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
}

}  // namespace salient::core
