#include "core/segment/plan_region.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "core/common/input_error.hpp"
#include "core/geometry/polygon_ops.hpp"
#include "core/segment/seg_opt.hpp"
#include "core/slicing/exact_solver.hpp"

namespace salient::core {
namespace {

// Whether a set of cut paths tiles the section: no path is a prefix of another and the shares
// (½ per cut) add up to one.
bool tiles(std::vector<std::vector<int>> paths) {
  std::sort(paths.begin(), paths.end());
  double share = 0;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (i > 0 && paths[i].size() >= paths[i - 1].size() &&
        std::equal(paths[i - 1].begin(), paths[i - 1].end(), paths[i].begin()))
      return false;
    share += std::ldexp(1.0, -static_cast<int>(paths[i].size()));
  }
  return std::fabs(share - 1) < 1e-12;
}

// The exact planner restricted to the allowed cells: fewest layers within the budget.
std::optional<LayerPlan> exact_on_allowed(const Objective& objective, std::vector<char> allowed,
                                          double epsilon, const RunContext& run) {
  ExactSolver solver(objective, run);
  solver.restrict_boundaries(std::move(allowed));
  const ZProfile& p = objective.profile();
  const double budget = objective.sm_fine() + epsilon;
  const double slack = 1e-12 * std::max(1.0, std::fabs(budget));
  for (int n = p.fewest_layers(); n <= p.most_layers(); ++n)
    if (solver.best_sm(n) <= budget + slack) return solver.plan(n);
  return std::nullopt;
}

// exact_on_allowed with the first `fixed` cells one fixed layer (0: none), as FirstLayerPlanner
// plans: the rest above it, with what the first layer leaves of ε. E(plan) = SM(first) +
// SM_above(rest) − SM(fine), so E ≤ ε ⇔ E_above(rest) ≤ ε + SM(fine) − SM(first) − SM_above(fine).
std::optional<LayerPlan> exact_above_first(const Objective& objective, std::vector<char> allowed,
                                           double epsilon, int fixed, const RunContext& run) {
  const ZProfile& p = objective.profile();
  if (fixed <= 0 || fixed >= p.cells()) return exact_on_allowed(objective, std::move(allowed), epsilon, run);
  std::optional<ZProfile> rest;
  try {
    rest.emplace(p.window(fixed, p.cells()));
  } catch (const InputError&) {  // what is left above cannot be cut into layers: plan it all
    return exact_on_allowed(objective, std::move(allowed), epsilon, run);
  }
  const Objective above(*rest, objective.metric());
  const double left = epsilon + objective.sm_fine() - objective.layer_sm(0, fixed) - above.sm_fine();
  std::vector<char> allowed_above(allowed.begin() + fixed, allowed.end());
  allowed_above.front() = 1;
  std::optional<LayerPlan> plan = exact_on_allowed(above, std::move(allowed_above), std::max(0.0, left), run);
  if (!plan) return plan;
  std::vector<int> boundaries{0};
  for (int b : plan->boundaries) boundaries.push_back(b + fixed);
  plan->boundaries = std::move(boundaries);
  return plan;
}

bool meets(const ZProfile& p, const PlanRegion& region, const std::vector<const PlanRegion*>& meet) {
  if (meet.empty()) return true;
  const std::vector<char> allowed = seam_allowed(p, region.first_cell, region.last_cell, meet);
  return std::all_of(region.plan.boundaries.begin(), region.plan.boundaries.end(),
                     [&](int b) { return allowed[b - region.first_cell] != 0; });
}

}  // namespace

bool touching(const PlanRegion& a, const PlanRegion& b) {
  if (!(a.side >= 0 && b.side >= 0 && (a.side != b.side || a.sub != b.sub) && a.first_cell < b.last_cell &&
        b.first_cell < a.last_cell))
    return false;
  if (a.clip.empty() || b.clip.empty()) return true;
  // Parts of a deeper cut may lie apart: only those sharing a piece of border print side by side.
  return intersection_area(offset({a.clip}, 0.01), {b.clip}) > 1e-9;
}

std::vector<char> seam_allowed(const ZProfile& whole, int first_cell, int last_cell,
                               const std::vector<const PlanRegion*>& neighbours) {
  std::vector<char> allowed(last_cell - first_cell + 1, 1);
  const int alpha = whole.min_cells();
  for (const PlanRegion* neighbour : neighbours)
    for (int b : neighbour->plan.boundaries)
      for (int k = std::max(first_cell, b - alpha + 1); k <= std::min(last_cell, b + alpha - 1); ++k)
        if (k != b) allowed[k - first_cell] = 0;
  allowed.front() = allowed.back() = 1;
  return allowed;
}

std::string check_regions(const ZProfile& whole, const std::vector<PlanRegion>& regions) {
  const int m = whole.cells(), alpha = whole.min_cells(), alpha_max = whole.max_cells();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const PlanRegion& region = regions[r];
    const std::string name = "region " + std::to_string(r);
    const auto& b = region.plan.boundaries;
    if (region.first_cell < 0 || region.last_cell > m || region.first_cell >= region.last_cell)
      return name + ": slab outside the model";
    if (b.size() < 2 || b.front() != region.first_cell || b.back() != region.last_cell)
      return name + ": its layers do not span its slab";
    for (std::size_t i = 0; i + 1 < b.size(); ++i) {
      const int w = b[i + 1] - b[i];
      if (w < alpha) return name + ": layer " + std::to_string(i) + " thinner than α";
      if (w > alpha_max) return name + ": layer " + std::to_string(i) + " thicker than ᾱ";
    }
    if (region.side < -1 || region.side > 1 || (region.side < 0 && !region.sub.empty()))
      return name + ": no such part";
    for (int s : region.sub)
      if (s != 0 && s != 1) return name + ": no such part";
  }
  // Coverage, slab by slab between the regions' horizontal boundaries.
  std::set<int> cuts{0, m};
  for (const PlanRegion& r : regions) cuts.insert(r.first_cell), cuts.insert(r.last_cell);
  for (auto it = cuts.begin(); std::next(it) != cuts.end(); ++it) {
    const int k = *it;
    std::vector<std::vector<int>> paths;
    int wholes = 0;
    for (const PlanRegion& r : regions) {
      if (r.first_cell > k || r.last_cell <= k) continue;
      if (r.side < 0)
        ++wholes;
      else
        paths.push_back(r.sub), paths.back().insert(paths.back().begin(), r.side);
    }
    if (!(wholes == 1 ? paths.empty() : wholes == 0 && tiles(paths)))
      return "height " + std::to_string(whole.z(k)) + " mm is not covered exactly once";
  }
  for (std::size_t r = 0; r < regions.size(); ++r)
    for (std::size_t q = r + 1; q < regions.size(); ++q) {
      if (!touching(regions[r], regions[q])) continue;
      const int lo = std::max(regions[r].first_cell, regions[q].first_cell);
      const int hi = std::min(regions[r].last_cell, regions[q].last_cell);
      std::set<int> heights;
      for (const PlanRegion* region : {&regions[r], &regions[q]})
        for (int b : region->plan.boundaries)
          if (b >= lo && b <= hi) heights.insert(b);
      int prev = -1;
      for (int h : heights) {
        if (prev >= 0 && h - prev < alpha)
          return "regions " + std::to_string(r) + " and " + std::to_string(q) + " print " +
                 std::to_string(whole.z(prev)) + " and " + std::to_string(whole.z(h)) +
                 " mm side by side, closer than α";
        prev = h;
      }
    }
  return {};
}

std::optional<PlanRegion> plan_region(const ZProfile& profile, PlanRegion region,
                                      std::optional<double> epsilon, const SegOptInput& in,
                                      const std::vector<const PlanRegion*>& candidates, const RunContext& run,
                                      const std::vector<const PlanRegion*>& align) {
  const int first = region.first_cell, last = region.last_cell;
  std::vector<const PlanRegion*> meet;  // those it touches
  for (const PlanRegion* n : candidates)
    if (touching(region, *n)) meet.push_back(n);
  const ZProfile slab = profile.window(first, last);
  const Objective objective(slab, in.metric);
  region.epsilon = epsilon ? *epsilon : objective.epsilon(in.rho);
  const int fixed = first == 0 ? in.first_cells : 0;  // a region on the bed starts with the first layer
  PlanRequest request{objective, nullptr, nullptr, PlanTarget::within(region.epsilon), in.seed, run};
  request.first_cells = fixed;
  LayerPlan local = in.planner.plan(request).plan;
  const auto to_whole = [&](const LayerPlan& plan) {
    region.plan.boundaries.clear();
    for (int b : plan.boundaries) region.plan.boundaries.push_back(b + first);
  };
  to_whole(local);
  if (!align.empty()) {
    // Only on `align`'s boundaries (where they keep the rule with its own neighbours): a part
    // whose finer partner must meet both it and those leaves the partner one set to avoid.
    std::vector<char> on = seam_allowed(profile, first, last, meet);
    std::vector<char> theirs(on.size(), 0);
    for (const PlanRegion* n : align)
      for (int b : n->plan.boundaries)
        if (b >= first && b <= last) theirs[b - first] = 1;
    for (std::size_t k = 1; k + 1 < on.size(); ++k) on[k] = on[k] && theirs[k];
    if (const auto aligned = exact_above_first(objective, on, region.epsilon, fixed, run)) {
      local = *aligned;
      to_whole(local);
    }
  }
  if (!meets(profile, region, meet)) {
    const auto constrained =
        exact_above_first(objective, seam_allowed(profile, first, last, meet), region.epsilon, fixed, run);
    if (!constrained) return std::nullopt;
    local = *constrained;
    to_whole(local);
  }
  region.error = objective.error(local);
  return region;
}

}  // namespace salient::core
