// fastest_within against every plan of small profiles: within the budget, its dual bound below
// the true optimum, and the optimum itself whenever it says so (always, at these sizes); exact
// under the time objective never slower than under the layer count.
#include "core/slicing/time_solver.hpp"

#include <doctest/doctest.h>

#include <functional>
#include <random>

#include "core/slicing/planner.hpp"
#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

namespace {

// Least time over every plan within `budget`, by enumeration.
double brute_force(const ZProfile& p, const Objective& obj, const LayerTimeModel& time, double budget) {
  double best = std::numeric_limits<double>::infinity();
  std::function<void(int, double, double)> go = [&](int j, double t, double sm) {
    if (sm > budget + 1e-12) return;  // SM only grows
    if (j == p.cells()) {
      best = std::min(best, t);
      return;
    }
    for (int w = p.min_cells(); w <= p.max_cells() && j + w <= p.cells(); ++w)
      go(j + w, t + time.layer_seconds(j, j + w), sm + obj.layer_sm(j, j + w));
  };
  go(0, 0, 0);
  return best;
}

}  // namespace

TEST_CASE("fastest_within: against every plan of small random profiles") {
  std::mt19937 rng(3);
  SlicingParams params;
  params.min_layer = 0.1;
  params.max_layer = 0.3;
  params.grid = 0.05;  // 2..6 cells a layer
  int optimal = 0, cases = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const Mesh mesh = salient::test::random_blob(rng, 10, 14, 1.2 + 0.1 * (trial % 4));
    const auto saliency = salient::test::random_saliency(rng, mesh.vertex_count());
    const ZProfile profile = ZProfile::build(mesh, saliency, params);
    const Objective obj(profile, trial % 2 ? Metric::paper : Metric::area);
    TimeModelParams tp;
    tp.min_layer_time = 0;  // make time follow the sections, not the floor
    const LayerTimeModel time(mesh, profile, tp);
    for (double rho : {0.02, 0.05, 0.2, 0.5}) {
      CAPTURE(trial);
      CAPTURE(rho);
      const double budget = obj.sm_fine() + obj.epsilon(rho);
      const TimedPlan t = fastest_within(obj, time, budget);
      REQUIRE(t.feasible);
      CHECK(check_plan(profile, t.plan) == "");
      CHECK(obj.sm(t.plan) <= budget + 1e-9);
      CHECK(t.seconds == doctest::Approx(time.seconds(t.plan)));
      const double best = brute_force(profile, obj, time, budget);
      CHECK(t.seconds >= best - 1e-9);
      CHECK(t.lower_bound <= best + 1e-9);
      // exact under the time objective: never slower than its fewest-layers plan.
      const PlanRequest by_time{obj, &mesh, nullptr,        PlanTarget::within(obj.epsilon(rho)),
                                1,   {},    PlanGoal::time, &time};
      PlanRequest by_layers = by_time;
      by_layers.goal = PlanGoal::layers;
      const LayerPlan fast = make_planner(PlannerKind::exact)->plan(by_time).plan;
      const LayerPlan few = make_planner(PlannerKind::exact)->plan(by_layers).plan;
      CHECK(time.seconds(fast) <= time.seconds(few) + 1e-9);
      CHECK(obj.error(fast) <= obj.epsilon(rho) + 1e-9);
      ++cases;
      if (t.proven_optimal) {
        ++optimal;
        CHECK(t.seconds == doctest::Approx(best).epsilon(1e-9));
      }
      // Looser budgets are never slower.
      const TimedPlan looser = fastest_within(obj, time, budget + obj.epsilon(0.1));
      CHECK(looser.seconds <= t.seconds + 1e-9);
    }
  }
  CHECK(optimal == cases);
}

TEST_CASE("fastest_within: an impossible budget gives the least-SM plan, marked infeasible") {
  std::mt19937 rng(4);
  const Mesh mesh = salient::test::random_blob(rng, 10, 14, 3);
  const ZProfile profile = ZProfile::build(mesh, std::vector<float>(mesh.vertex_count(), 1.0f), {});
  const Objective obj(profile, Metric::area);
  const LayerTimeModel time(mesh, profile);
  const TimedPlan t = fastest_within(obj, time, obj.sm_fine() - 1);
  CHECK_FALSE(t.feasible);
  CHECK(check_plan(profile, t.plan) == "");
}
