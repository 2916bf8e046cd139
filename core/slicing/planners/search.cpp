// Parameter searches shared by the planners: every planner answers both targets (Table 1).
#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "core/slicing/planners/planners.hpp"

namespace salient::core::planners {

int clamp_count(const ZProfile& profile, int requested, std::string& note) {
  const int lo = profile.fewest_layers(), hi = profile.most_layers();
  const int n = std::clamp(requested, lo, hi);
  if (n != requested)
    note = "asked for " + std::to_string(requested) + " layers; valid plans have " + std::to_string(lo) +
           " to " + std::to_string(hi) + ", so " + std::to_string(n);
  return n;
}

PlanResult search_count(const PlanRequest& request, const std::function<LayerPlan(int)>& plan) {
  const ZProfile& profile = request.objective.profile();
  PlanResult result;
  if (request.target.layers) {
    result.plan = plan(clamp_count(profile, *request.target.layers, result.note));
    return result;
  }
  const double eps = request.target.epsilon.value_or(0);
  for (int n = profile.fewest_layers(); n <= profile.most_layers(); ++n) {
    request.run.check();
    LayerPlan p = plan(n);
    if (request.objective.error(p) <= eps + 1e-12 * std::max(1.0, eps) || n == profile.most_layers()) {
      result.plan = std::move(p);
      return result;
    }
  }
  return result;
}

PlanResult search_parameter(const PlanRequest& request, double lo, double hi,
                            const std::function<LayerPlan(double)>& plan) {
  const Objective& obj = request.objective;
  PlanResult result;
  constexpr int iterations = 48;
  if (request.target.layers) {
    const int want = clamp_count(obj.profile(), *request.target.layers, result.note);
    int best_gap = std::numeric_limits<int>::max();
    double best_error = 0;
    auto consider = [&](LayerPlan p) {
      const int gap = std::abs(p.layer_count() - want);
      const double e = obj.error(p);
      if (gap < best_gap || (gap == best_gap && e < best_error)) {
        best_gap = gap;
        best_error = e;
        result.plan = std::move(p);
      }
    };
    // A scan first: the count need not fall monotonically with the parameter (adapslice's does
    // not), so bisect inside the bracket whose ends come closest to the target.
    constexpr int scan = 16;
    std::vector<double> ps(scan + 1);
    std::vector<int> counts(scan + 1);
    for (int s = 0; s <= scan; ++s) {
      request.run.check();
      ps[s] = lo + (hi - lo) * s / scan;
      LayerPlan p = plan(ps[s]);
      counts[s] = p.layer_count();
      consider(std::move(p));
    }
    int bracket = -1;
    for (int s = 0; s < scan && bracket < 0; ++s)
      if ((counts[s] - want) * (counts[s + 1] - want) <= 0) bracket = s;
    if (bracket >= 0) {
      lo = ps[bracket];
      hi = ps[bracket + 1];
      const bool falling = counts[bracket] >= counts[bracket + 1];
      for (int it = 0; it < iterations && best_gap > 0; ++it) {
        request.run.check();
        const double mid = 0.5 * (lo + hi);
        LayerPlan p = plan(mid);
        const int count = p.layer_count();
        consider(std::move(p));
        if ((count > want) == falling)
          lo = mid;
        else
          hi = mid;
      }
    }
    if (best_gap > 0 && result.note.empty())
      result.note = "no parameter gives exactly " + std::to_string(want) + " layers; nearest is " +
                    std::to_string(result.plan.layer_count());
    return result;
  }
  const double eps = request.target.epsilon.value_or(0);
  const double slack = 1e-12 * std::max(1.0, eps);
  bool found = false;
  auto consider = [&](LayerPlan p) {
    const double e = obj.error(p);
    if (e > eps + slack) return false;
    if (!found || p.layer_count() < result.plan.layer_count() ||
        (p.layer_count() == result.plan.layer_count() && e < obj.error(result.plan))) {
      result.plan = std::move(p);
      found = true;
    }
    return true;
  };
  if (consider(plan(hi))) return result;
  if (!consider(plan(lo))) {
    result.plan = fine_plan(obj.profile());
    result.note = "no parameter keeps E within epsilon; the finest plan is used";
    return result;
  }
  for (int it = 0; it < iterations; ++it) {
    request.run.check();
    const double mid = 0.5 * (lo + hi);
    if (consider(plan(mid)))
      lo = mid;
    else
      hi = mid;
  }
  return result;
}

}  // namespace salient::core::planners
