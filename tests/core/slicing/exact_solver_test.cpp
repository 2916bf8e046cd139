// ExactSolver against brute force on random small models: it must find the least SM for every
// layer count and the fewest layers within every budget, under both metrics.
#include "core/slicing/exact_solver.hpp"

#include <doctest/doctest.h>

#include <functional>
#include <limits>

#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

namespace {

// Least SM for each layer count, over every valid plan (enumerated).
std::vector<double> brute_force(const Objective& obj) {
  const ZProfile& p = obj.profile();
  std::vector<double> best(p.most_layers() + 1, std::numeric_limits<double>::infinity());
  std::function<void(int, int, double)> go = [&](int at, int layers, double sm) {
    if (at == p.cells()) {
      best[layers] = std::min(best[layers], sm);
      return;
    }
    for (int w = p.min_cells(); w <= p.max_cells() && at + w <= p.cells(); ++w)
      go(at + w, layers + 1, sm + obj.layer_sm(at, at + w));
  };
  go(0, 0, 0);
  return best;
}

}  // namespace

TEST_CASE("exact equals brute force on random small profiles") {
  std::mt19937 rng(7);
  int checked = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const double height = std::uniform_real_distribution<double>(0.9, 1.6)(rng);
    const Mesh m = salient::test::random_blob(rng, 6, 7, height);
    const std::vector<float> s = salient::test::random_saliency(rng, m.vertex_count());
    const ZProfile p = ZProfile::build(m, s, {0.1, 0.3, 0.025});
    for (Metric metric : {Metric::area, Metric::paper}) {
      CAPTURE(trial);
      const Objective obj(p, metric);
      const std::vector<double> truth = brute_force(obj);
      ExactSolver solver(obj);
      for (int n = p.fewest_layers(); n <= p.most_layers(); ++n) {
        CAPTURE(n);
        CHECK(solver.best_sm(n) == doctest::Approx(truth[n]).epsilon(1e-12));
        const LayerPlan plan = solver.plan(n);
        CHECK(plan.layer_count() == n);
        CHECK(check_plan(p, plan) == "");
        CHECK(obj.sm(plan) == doctest::Approx(truth[n]).epsilon(1e-12));
        ++checked;
      }
      for (double rho : {0.0, 0.01, 0.05, 0.2, 0.5, 1.0}) {
        const double budget = obj.sm_fine() + obj.epsilon(rho);
        int fewest = p.most_layers();
        for (int n = p.fewest_layers(); n <= p.most_layers(); ++n)
          if (truth[n] <= budget + 1e-12 * std::max(1.0, budget)) {
            fewest = n;
            break;
          }
        CHECK(solver.fewest_layers_within(budget) == fewest);
      }
    }
  }
  CHECK(checked > 100);
}
