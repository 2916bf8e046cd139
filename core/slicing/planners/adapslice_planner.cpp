// adapslice: the paper's method (§4, Fig. 4). Initialise by greedy merging (hms) to ε, then in
// rounds: TimeOpt (eq. 6, weights eq. 7) shrinks layers that can go, the layers left thinner
// than α are degenerated in order of merge cost (eq. 8) while E ≤ ε, and VisualOpt (eq. 9)
// re-places the remaining boundaries. Both LPs use each layer's cost per cell frozen at the
// current plan and are solved exactly (lp_solvers); the true E is re-evaluated after every
// step. Rounds stop when VisualOpt no longer lowers the layer count; the result is the best
// valid plan seen with E ≤ ε. Everything is in grid cells, so every plan lies on the grid.
//
// Where the paper is silent or its assumptions break:
// - A frozen cost per unit height is exact for the paper's metric (eq. 1) but under-estimates
//   ours, whose stair-step volume grows with h²: a TimeOpt solution taken as it is overshoots ε
//   by far. So TimeOpt only nominates the redundant layers (those it drives below α); they are
//   then degenerated as the paper says (eq. 8: cheapest merge first, the neighbour absorbing the
//   thickness) on the current valid plan, with the true E checked at every merge.
// - A lone VisualOpt LP puts every layer at α or ᾱ (a vertex), far from the optimum of the true
//   E under our metric; VisualOpt is solved as a sequence of exact LPs in a shrinking trust
//   region, each step kept only if the true E drops.
// Every accepted plan has E ≤ ε, and the layer count never rises along the trace.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/slicing/lp_solvers.hpp"
#include "core/slicing/merge_sequence.hpp"
#include "core/slicing/planners/planners.hpp"

namespace salient::core::planners {
namespace {

constexpr double eta = 1e-8;  // eq. 7
constexpr int max_rounds = 20;

std::vector<double> cost_per_cell(const Objective& obj, const LayerPlan& plan) {
  std::vector<double> g(plan.layer_count());
  for (int i = 0; i < plan.layer_count(); ++i) {
    const int a = plan.boundaries[i], b = plan.boundaries[i + 1];
    g[i] = obj.layer_sm(a, b) / (b - a);
  }
  return g;
}

// Eq. 8: merges the redundant layers into their cheaper neighbour, cheapest first, while the
// loss stays within ε and the merged layer within ᾱ. `redundant` has one flag per layer.
LayerPlan degenerate(const Objective& obj, LayerPlan plan, std::vector<bool> redundant, double eps) {
  const ZProfile& p = obj.profile();
  double error = obj.error(plan);
  while (true) {
    double best = std::numeric_limits<double>::infinity();
    int best_boundary = -1, best_layer = -1;
    for (int i = 0; i < plan.layer_count(); ++i) {
      if (!redundant[i]) continue;
      const int a = plan.boundaries[i], b = plan.boundaries[i + 1];
      if (i > 0) {  // merge with the layer below: drop boundary i
        const int lo = plan.boundaries[i - 1];
        const double cost = obj.layer_sm(lo, b) - obj.layer_sm(lo, a) - obj.layer_sm(a, b);
        if (b - lo <= p.max_cells() && cost < best) best = cost, best_boundary = i, best_layer = i;
      }
      if (i + 1 < plan.layer_count()) {  // merge with the layer above: drop boundary i + 1
        const int hi = plan.boundaries[i + 2];
        const double cost = obj.layer_sm(a, hi) - obj.layer_sm(a, b) - obj.layer_sm(b, hi);
        if (hi - a <= p.max_cells() && cost < best) best = cost, best_boundary = i + 1, best_layer = i;
      }
    }
    if (best_boundary < 0 || error + best > eps) return plan;
    plan.boundaries.erase(plan.boundaries.begin() + best_boundary);
    // The two layers are one now, and it is not redundant.
    redundant.erase(redundant.begin() + best_layer);
    redundant[best_boundary - 1] = false;
    error += best;
  }
}

// VisualOpt (eq. 9) as a sequence of exact LPs, each within a trust region of `r` cells around
// the current widths: a lone LP puts every layer at α or ᾱ (a vertex), which under our metric's
// h² growth is far from the optimum of the true E. A step is kept only if the true E drops (the
// first, which makes every layer valid, always is); r halves on a failed step.
LayerPlan visual_opt(const Objective& obj, const LayerPlan& start) {
  const ZProfile& p = obj.profile();
  const int n = start.layer_count();
  LayerPlan plan = start;
  bool valid = check_plan(p, plan).empty();
  double error = obj.error(plan);
  for (int r = p.max_cells() - p.min_cells(); r >= 1;) {
    std::vector<int> lo(n), hi(n);
    for (int i = 0; i < n; ++i) {
      const int w = plan.width(i);
      lo[i] = std::max(p.min_cells(), w - r);
      hi[i] = std::max(lo[i], std::min(p.max_cells(), w + r));
    }
    const auto widths = solve_visual_lp(cost_per_cell(obj, plan), lo, hi, p.cells());
    if (!widths) {
      if (!valid)
        return plan_from_widths(*solve_visual_lp(cost_per_cell(obj, plan), std::vector<int>(n, p.min_cells()),
                                                 std::vector<int>(n, p.max_cells()), p.cells()));
      r /= 2;
      continue;
    }
    LayerPlan next = plan_from_widths(*widths);
    const double e = obj.error(next);
    if (!valid || e < error - 1e-12 * std::max(1.0, error)) {
      plan = std::move(next);
      error = e;
      valid = true;
    } else {
      r /= 2;
    }
  }
  return plan;
}

struct Run {
  LayerPlan plan;
  std::vector<PlanStep> trace;
};

Run adapslice(const Objective& obj, double eps, const RunContext& run) {
  const ZProfile& p = obj.profile();
  Run out;
  auto record = [&](const char* step, const LayerPlan& plan) {
    out.trace.push_back({step, plan.layer_count(), obj.error(plan)});
  };
  const auto loss = [&obj](int i, int j, int k) {
    return obj.layer_sm(i, k) - obj.layer_sm(i, j) - obj.layer_sm(j, k);
  };
  const MergeSequence seq(fine_plan(p), p.max_cells(), loss, loss, run);
  LayerPlan current = seq.at(seq.fewest_within(eps - obj.error(seq.at(seq.most()))));
  record("init", current);
  current = visual_opt(obj, current);  // re-place the initial boundaries before any removal
  record("VisualOpt", current);
  out.plan = current;
  for (int round = 0; round < max_rounds; ++round) {
    run.check();
    run.report("adapslice", static_cast<double>(round) / max_rounds);
    // TimeOpt on the current plan: which layers does the weighted-l1 LP want gone?
    const std::vector<double> g = cost_per_cell(obj, current);
    std::vector<double> c(g.size());
    for (int i = 0; i < current.layer_count(); ++i)
      c[i] = 1.0 / (eta + (current.width(i) - p.min_cells()) * p.grid());
    const TimeLpSolution t =
        solve_time_lp(c, g, std::vector<double>(g.size(), p.max_cells()), p.cells(), eps + obj.sm_fine());
    if (!t.feasible) break;
    std::vector<bool> redundant(g.size());
    for (std::size_t i = 0; i < g.size(); ++i) redundant[i] = t.x[i] < p.min_cells();
    const LayerPlan merged = degenerate(obj, current, redundant, eps);
    if (merged.layer_count() == current.layer_count()) break;  // nothing could go
    record("degenerate", merged);
    const LayerPlan visual = visual_opt(obj, merged);
    record("VisualOpt", visual);
    out.plan = visual;
    current = visual;
  }
  return out;
}

class AdapslicePlanner : public Planner {
 public:
  std::string_view name() const override { return "adapslice"; }
  PlanResult plan(const PlanRequest& request) const override {
    const Objective& obj = request.objective;
    if (request.target.layers) {
      // Its own parameter is ε: search it for the requested count.
      PlanResult r = search_parameter(request, 0.0, obj.e_coarse(),
                                      [&](double eps) { return adapslice(obj, eps, request.run).plan; });
      return r;
    }
    Run r = adapslice(obj, request.target.epsilon.value_or(0), request.run);
    return {std::move(r.plan), "", std::move(r.trace)};
  }
};

}  // namespace

std::unique_ptr<Planner> make_adapslice() {
  return std::make_unique<AdapslicePlanner>();
}

}  // namespace salient::core::planners
