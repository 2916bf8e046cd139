// cusp: Dolenc & Mäkelä 1994, "Slicing procedures for layered manufacturing": sweeping up,
// each layer is as thick as keeps the cusp height h·cos θ within c (cos θ the largest |n_z| in
// the layer), between α and ᾱ.
// stepwise: Sabourin et al. 1996, "Adaptive slicing using stepwise uniform refinement": slabs
// of ᾱ, each split into ⌈ᾱ / h_req⌉ equal layers, h_req = c / cos θ of the slab.
// Both are geometric (no saliency); c is the parameter searched for each target.
#include <algorithm>
#include <cmath>

#include "core/slicing/planners/planners.hpp"

namespace salient::core::planners {
namespace {

// Largest width in [wmin, wmax] starting at cell k whose cusp height stays within c, adjusted
// so that what remains above can still be cut into valid layers.
int cusp_width(const ZProfile& p, int k, double c) {
  const int m = p.cells(), wmin = p.min_cells(), wmax = p.max_cells();
  const int remaining = m - k;
  if (remaining <= wmax && remaining >= wmin) {
    // The rest fits in one layer; take it if the cusp allows, else fall through.
    if ((p.z(m) - p.z(k)) * p.max_cos(k, m) <= c) return remaining;
  }
  int w = std::min(wmax, remaining);
  while (w > wmin && (p.z(k + w) - p.z(k)) * p.max_cos(k, k + w) > c) --w;
  w = std::max(w, std::min(wmin, remaining));
  // Leave a remainder that valid layers can fill: never 1..wmin-1 cells.
  const int left = remaining - w;
  if (left > 0 && left < wmin) {
    if (remaining <= wmax)
      w = remaining;  // absorb it
    else
      w = remaining - wmin;  // leave exactly one thin layer
  }
  return w;
}

LayerPlan cusp_plan(const ZProfile& p, double c) {
  LayerPlan plan;
  plan.boundaries.push_back(0);
  while (plan.boundaries.back() < p.cells())
    plan.boundaries.push_back(plan.boundaries.back() + cusp_width(p, plan.boundaries.back(), c));
  return plan;
}

LayerPlan stepwise_plan(const ZProfile& p, double c) {
  const LayerPlan slabs = coarse_plan(p);
  std::vector<int> widths;
  for (int s = 0; s < slabs.layer_count(); ++s) {
    const int a = slabs.boundaries[s], b = slabs.boundaries[s + 1], w = b - a;
    const double cos = p.max_cos(a, b);
    const double h_req = cos > 0 ? c / cos : p.params().max_layer;
    const double slab_height = p.z(b) - p.z(a);
    int parts = h_req > 0 ? static_cast<int>(std::ceil(slab_height / h_req - 1e-9)) : w;
    parts = std::clamp(parts, 1, std::max(1, w / p.min_cells()));
    for (int i = 0; i < parts; ++i) widths.push_back((i + 1) * w / parts - i * w / parts);
  }
  return plan_from_widths(widths);
}

class CuspPlanner : public Planner {
 public:
  explicit CuspPlanner(bool stepwise) : stepwise_(stepwise) {}
  std::string_view name() const override { return stepwise_ ? "stepwise" : "cusp"; }
  PlanResult plan(const PlanRequest& request) const override {
    const ZProfile& p = request.objective.profile();
    // c = 0 forces α everywhere; c = ᾱ allows ᾱ everywhere (cos θ ≤ 1).
    return search_parameter(request, 0.0, p.params().max_layer,
                            [&](double c) { return stepwise_ ? stepwise_plan(p, c) : cusp_plan(p, c); });
  }

 private:
  bool stepwise_;
};

}  // namespace

std::unique_ptr<Planner> make_cusp() {
  return std::make_unique<CuspPlanner>(false);
}
std::unique_ptr<Planner> make_stepwise() {
  return std::make_unique<CuspPlanner>(true);
}

}  // namespace salient::core::planners
