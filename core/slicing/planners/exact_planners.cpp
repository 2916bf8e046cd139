// exact (ours, ALGORITHMS.md §4), ceo (exact on geometry alone, paper §7 "CEO") and random
// (another plan's layers in random order, paper §7 "Random").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/slicing/exact_solver.hpp"
#include "core/slicing/planners/planners.hpp"
#include "core/slicing/time_solver.hpp"

namespace salient::core::planners {
namespace {

class ExactPlanner : public Planner {
 public:
  std::string_view name() const override { return "exact"; }
  PlanResult plan(const PlanRequest& request) const override {
    ExactSolver solver(request.objective, request.run);
    PlanResult result;
    int n;
    if (request.target.layers) {
      n = clamp_count(request.objective.profile(), *request.target.layers, result.note);
    } else {
      n = solver.fewest_layers_within(request.objective.sm_fine() + request.target.epsilon.value_or(0));
    }
    result.plan = solver.plan(n);
    if (request.goal == PlanGoal::time && request.time && !request.target.layers) fastest(request, result);
    return result;
  }

 private:
  // The time objective: the fastest plan within ε (time_solver), unless the fewest layers'
  // plan is as fast — so `--objective time` never takes longer than `layers` by the model.
  static void fastest(const PlanRequest& request, PlanResult& result) {
    const Objective& obj = request.objective;
    const TimedPlan t =
        fastest_within(obj, *request.time, obj.sm_fine() + request.target.epsilon.value_or(0), request.run);
    if (!t.feasible || t.seconds >= request.time->seconds(result.plan)) return;
    result.plan = t.plan;
    if (!t.proven_optimal) {
      char buf[200];
      std::snprintf(
          buf, sizeof buf,
          "time objective: within %.0f s (%.2f %%) of the fastest plan; the exact search was cut short, "
          "so not proven optimal",
          t.seconds - t.lower_bound, 100 * (t.seconds / t.lower_bound - 1));
      result.note = buf;
    }
  }
};

// Plans chosen by saliency-free geometry, judged by the request's (saliency) objective.
class CeoPlanner : public Planner {
 public:
  std::string_view name() const override { return "ceo"; }
  PlanResult plan(const PlanRequest& request) const override {
    const Objective own(request.objective.profile(), request.objective.metric(), true);
    const Objective& geometric = request.geometric ? *request.geometric : own;
    ExactSolver solver(geometric, request.run);
    return search_count(request, [&](int n) { return solver.plan(n); });
  }
};

class RandomPlanner : public Planner {
 public:
  std::string_view name() const override { return "random"; }
  PlanResult plan(const PlanRequest& request) const override {
    ExactSolver solver(request.objective, request.run);
    return search_count(request, [&](int n) {
      std::vector<int> widths = widths_of(solver.plan(n));
      std::mt19937_64 rng(request.seed);
      std::shuffle(widths.begin(), widths.end(), rng);
      return plan_from_widths(widths);
    });
  }
};

}  // namespace

std::unique_ptr<Planner> make_exact() {
  return std::make_unique<ExactPlanner>();
}
std::unique_ptr<Planner> make_ceo() {
  return std::make_unique<CeoPlanner>();
}
std::unique_ptr<Planner> make_random() {
  return std::make_unique<RandomPlanner>();
}

}  // namespace salient::core::planners
