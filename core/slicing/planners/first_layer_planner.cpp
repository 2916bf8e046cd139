// The fixed first layer (PrusaSlicer's first_layer_height): a first layer thin enough to hold
// nothing extrudable fails on the bed, and PrusaSlicer refuses a 3MF profile with one. Any
// planner then plans the profile above it. Under an ε target the budget left for the rest is
// exact: E(plan) = SM(first) + SM_above(rest) − SM(fine), so E ≤ ε ⇔ E_above(rest) ≤ ε + SM(fine)
// − SM(first) − SM_above(fine above).
#include <algorithm>
#include <optional>

#include "core/common/input_error.hpp"
#include "core/slicing/planners/planners.hpp"

namespace salient::core::planners {
namespace {

class FirstLayerPlanner : public Planner {
 public:
  explicit FirstLayerPlanner(std::unique_ptr<Planner> inner) : inner_(std::move(inner)) {}
  std::string_view name() const override { return inner_->name(); }

  PlanResult plan(const PlanRequest& request) const override {
    const Objective& whole = request.objective;
    const ZProfile& p = whole.profile();
    const int f = request.first_cells, m = p.cells();
    if (f <= 0 || f >= m) return inner_->plan(request);
    std::optional<ZProfile> above;
    try {
      above.emplace(p.window(f, m));
    } catch (const InputError&) {  // what is left above cannot be cut into layers: plan it all
      PlanResult r = inner_->plan(request);
      r.note = join(r.note, "the first layer is not fixed: the model above it cannot be cut into layers");
      return r;
    }
    const Objective objective(*above, whole.metric(), whole.geometric());
    const Objective geometric(*above, whole.metric(), true);
    std::optional<LayerTimeModel> time;
    if (request.time) time.emplace(request.time->window(f, m));
    // ha13 cuts the mesh's own sections: the mesh moved down by the first layer.
    std::optional<Mesh> lowered;
    if (request.mesh && inner_->name() == "ha13") {
      lowered.emplace(*request.mesh);
      for (Vec3& v : lowered->positions) v.z -= p.z(f);
    }
    const double fixed = whole.layer_sm(0, f);
    // E of a plan above, as E of the whole plan: + shift.
    const double shift = fixed + objective.sm_fine() - whole.sm_fine();
    PlanTarget target = request.target;
    if (target.epsilon) target.epsilon = std::max(0.0, *target.epsilon - shift);
    if (target.layers) target.layers = std::max(1, *target.layers - 1);
    const PlanRequest sub{
        objective,    lowered ? &*lowered : nullptr, &geometric, target, request.seed, request.run,
        request.goal, time ? &*time : nullptr,       0};
    PlanResult r = inner_->plan(sub);
    std::vector<int> boundaries{0};
    for (int b : r.plan.boundaries) boundaries.push_back(b + f);
    r.plan.boundaries = std::move(boundaries);
    for (PlanStep& s : r.trace) {
      s.layers += 1;
      s.error += shift;
    }
    return r;
  }

 private:
  static std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "; " + b; }
  std::unique_ptr<Planner> inner_;
};

}  // namespace

std::unique_ptr<Planner> with_first_layer(std::unique_ptr<Planner> planner) {
  return std::make_unique<FirstLayerPlanner>(std::move(planner));
}

}  // namespace salient::core::planners
