// LayerPlan: layer boundaries on the profile's grid, and the uniform plans every other is
// measured against.
#pragma once

#include <string>
#include <vector>

namespace salient::core {

class ZProfile;

// boundaries[0] = 0 < boundaries[1] < … < boundaries[N] = M, in grid cells; layer i spans
// cells [boundaries[i], boundaries[i+1]).
struct LayerPlan {
  std::vector<int> boundaries;

  int layer_count() const { return boundaries.empty() ? 0 : static_cast<int>(boundaries.size()) - 1; }
  int width(int layer) const { return boundaries[layer + 1] - boundaries[layer]; }
  bool operator==(const LayerPlan&) const = default;
};

// N layers whose widths differ by at most one cell (the plan "uniform" means on a grid).
// Requires profile.fewest_layers() <= n <= profile.most_layers().
LayerPlan uniform_plan(const ZProfile& profile, int n);
LayerPlan fine_plan(const ZProfile& profile);    // uniform α: the most layers
LayerPlan coarse_plan(const ZProfile& profile);  // uniform ᾱ: the fewest

// The most and fewest layers a printer makes of `profile` with its first layer fixed at
// `first_cells` (0: free, as the profile's own most_layers and fewest_layers): what "fine" and
// "coarse" count wherever they are shown, so they agree with the fine and coarse planners' plans.
int finest_layer_count(const ZProfile& profile, int first_cells);
int fewest_layer_count(const ZProfile& profile, int first_cells);

// Empty if `plan` is valid for `profile` (starts at 0, ends at M, every width within α..ᾱ),
// else what is wrong with it.
std::string check_plan(const ZProfile& profile, const LayerPlan& plan);

// Plan from per-layer widths in cells (which must sum to M).
LayerPlan plan_from_widths(const std::vector<int>& widths);
std::vector<int> widths_of(const LayerPlan& plan);

}  // namespace salient::core
