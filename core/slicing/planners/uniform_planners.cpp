// fine, coarse and uniform (paper §7 "GroundTruth" and "Uniform").
#include "core/slicing/planners/planners.hpp"

namespace salient::core::planners {
namespace {

class FixedPlanner : public Planner {
 public:
  explicit FixedPlanner(bool fine) : fine_(fine) {}
  std::string_view name() const override { return fine_ ? "fine" : "coarse"; }
  PlanResult plan(const PlanRequest& request) const override {
    const ZProfile& p = request.objective.profile();
    return {fine_ ? fine_plan(p) : coarse_plan(p), "", {}};
  }

 private:
  bool fine_;
};

class UniformPlanner : public Planner {
 public:
  std::string_view name() const override { return "uniform"; }
  PlanResult plan(const PlanRequest& request) const override {
    const ZProfile& profile = request.objective.profile();
    return search_count(request, [&](int n) { return uniform_plan(profile, n); });
  }
};

}  // namespace

std::unique_ptr<Planner> make_fine() {
  return std::make_unique<FixedPlanner>(true);
}
std::unique_ptr<Planner> make_coarse() {
  return std::make_unique<FixedPlanner>(false);
}
std::unique_ptr<Planner> make_uniform() {
  return std::make_unique<UniformPlanner>();
}

}  // namespace salient::core::planners
