#include "core/segment/plan_region.hpp"

#include <algorithm>
#include <cstdlib>
#include <set>

namespace salient::core {

bool touching(const PlanRegion& a, const PlanRegion& b) {
  return a.side >= 0 && b.side >= 0 && a.side != b.side && a.first_cell < b.last_cell && b.first_cell < a.last_cell;
}

std::vector<char> seam_allowed(const ZProfile& whole, int first_cell, int last_cell, const PlanRegion& neighbour) {
  std::vector<char> allowed(last_cell - first_cell + 1, 1);
  const int alpha = whole.min_cells();
  for (int b : neighbour.plan.boundaries)
    for (int k = std::max(first_cell, b - alpha + 1); k <= std::min(last_cell, b + alpha - 1); ++k)
      if (k != b) allowed[k - first_cell] = 0;
  allowed.front() = allowed.back() = 1;
  return allowed;
}

std::string check_regions(const ZProfile& whole, const std::vector<PlanRegion>& regions) {
  const int m = whole.cells(), alpha = whole.min_cells(), alpha_max = whole.max_cells();
  std::vector<int> whole_cover(m, 0), side_cover[2] = {std::vector<int>(m, 0), std::vector<int>(m, 0)};
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const PlanRegion& region = regions[r];
    const std::string name = "region " + std::to_string(r);
    const auto& b = region.plan.boundaries;
    if (region.first_cell < 0 || region.last_cell > m || region.first_cell >= region.last_cell)
      return name + ": slab outside the model";
    if (b.size() < 2 || b.front() != region.first_cell || b.back() != region.last_cell)
      return name + ": its layers do not span its slab";
    for (std::size_t i = 0; i + 1 < b.size(); ++i) {
      const int w = b[i + 1] - b[i];
      if (w < alpha) return name + ": layer " + std::to_string(i) + " thinner than α";
      if (w > alpha_max) return name + ": layer " + std::to_string(i) + " thicker than ᾱ";
    }
    if (region.side < -1 || region.side > 1) return name + ": no such side";
    for (int k = region.first_cell; k < region.last_cell; ++k)
      ++(region.side < 0 ? whole_cover[k] : side_cover[region.side][k]);
  }
  for (int k = 0; k < m; ++k) {
    const bool once = whole_cover[k] == 1 ? side_cover[0][k] == 0 && side_cover[1][k] == 0
                                          : whole_cover[k] == 0 && side_cover[0][k] == 1 && side_cover[1][k] == 1;
    if (!once) return "height " + std::to_string(whole.z(k)) + " mm is not covered exactly once";
  }
  for (std::size_t r = 0; r < regions.size(); ++r)
    for (std::size_t q = r + 1; q < regions.size(); ++q) {
      if (!touching(regions[r], regions[q])) continue;
      const int lo = std::max(regions[r].first_cell, regions[q].first_cell);
      const int hi = std::min(regions[r].last_cell, regions[q].last_cell);
      std::set<int> heights;
      for (const PlanRegion* region : {&regions[r], &regions[q]})
        for (int b : region->plan.boundaries)
          if (b >= lo && b <= hi) heights.insert(b);
      int prev = -1;
      for (int h : heights) {
        if (prev >= 0 && h - prev < alpha)
          return "regions " + std::to_string(r) + " and " + std::to_string(q) + " print " + std::to_string(whole.z(prev)) +
                 " and " + std::to_string(whole.z(h)) + " mm side by side, closer than α";
        prev = h;
      }
    }
  return {};
}

}  // namespace salient::core
