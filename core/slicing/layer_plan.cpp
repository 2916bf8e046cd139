// LayerPlan helpers.
#include "core/slicing/layer_plan.hpp"

#include <stdexcept>

#include "core/slicing/z_profile.hpp"

namespace salient::core {

LayerPlan uniform_plan(const ZProfile& profile, int n) {
  const int m = profile.cells();
  if (n < profile.fewest_layers() || n > profile.most_layers())
    throw std::invalid_argument("uniform_plan: no valid plan with " + std::to_string(n) + " layers");
  LayerPlan plan;
  plan.boundaries.resize(n + 1);
  for (int i = 0; i <= n; ++i) plan.boundaries[i] = static_cast<int>(static_cast<long long>(i) * m / n);
  return plan;
}

int finest_layer_count(const ZProfile& p, int first_cells) {
  if (first_cells <= 0 || first_cells >= p.cells()) return p.most_layers();
  return 1 + (p.cells() - first_cells) / p.min_cells();
}

int fewest_layer_count(const ZProfile& p, int first_cells) {
  if (first_cells <= 0 || first_cells >= p.cells()) return p.fewest_layers();
  return 1 + (p.cells() - first_cells + p.max_cells() - 1) / p.max_cells();
}

LayerPlan fine_plan(const ZProfile& profile) {
  return uniform_plan(profile, profile.most_layers());
}
LayerPlan coarse_plan(const ZProfile& profile) {
  return uniform_plan(profile, profile.fewest_layers());
}

std::string check_plan(const ZProfile& profile, const LayerPlan& plan) {
  if (plan.boundaries.size() < 2) return "plan has no layers";
  if (plan.boundaries.front() != 0) return "plan does not start at z = 0";
  if (plan.boundaries.back() != profile.cells()) return "plan does not end at the model's top";
  for (int i = 0; i < plan.layer_count(); ++i) {
    const int w = plan.width(i);
    if (w < profile.min_cells() || w > profile.max_cells())
      return "layer " + std::to_string(i) + " is " + std::to_string(w) + " cells thick, outside " +
             std::to_string(profile.min_cells()) + ".." + std::to_string(profile.max_cells());
  }
  return {};
}

LayerPlan plan_from_widths(const std::vector<int>& widths) {
  LayerPlan plan;
  plan.boundaries.reserve(widths.size() + 1);
  plan.boundaries.push_back(0);
  for (int w : widths) plan.boundaries.push_back(plan.boundaries.back() + w);
  return plan;
}

std::vector<int> widths_of(const LayerPlan& plan) {
  std::vector<int> w(plan.layer_count());
  for (int i = 0; i < plan.layer_count(); ++i) w[i] = plan.width(i);
  return w;
}

}  // namespace salient::core
