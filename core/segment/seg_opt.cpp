// SegOpt. Choices the paper leaves open (ALGORITHMS.md §5):
// - Each part is profiled on the whole model's grid (its own faces, cut along the plane; the cut
//   face itself is inside the print and adds nothing), so the parts' layers can meet.
// - "Average SM" of a part within a slab is compared as its relative loss there: (SM of its plan
//   − SM of the slab's finest) / (SM of the slab's coarsest − finest), 0 where it is printed as
//   finely as possible and 1 where as coarsely; so the 0.03 threshold is on the scale of ρ.
// - Slabs must each be printable in layers of α..ᾱ: critical heights too close to the previous
//   one (or to the top) are dropped.
// - In a slab that keeps the cut, the part with the larger loss (the coarser one) is planned first
//   and the finer one must meet it (PlanRegion's seam rule): inside a thick layer a thin one keeps
//   most of its choices, while a thick layer held to a thin one's boundaries loses most of its
//   own. If it cannot within its ε, the slab is merged instead.
#include "core/segment/seg_opt.hpp"

#include <algorithm>
#include <cmath>

#include "core/segment/mesh_split.hpp"
#include "core/slicing/exact_solver.hpp"

namespace salient::core {
namespace {

bool printable(const ZProfile& p, int cells) {
  return cells >= p.min_cells() && (cells + p.max_cells() - 1) / p.max_cells() <= cells / p.min_cells();
}

// The part's relative loss within [first, last): its plan's layers cut to the slab.
double relative_loss(const ZProfile& part, Metric metric, const LayerPlan& plan, int first, int last) {
  const ZProfile slab = part.window(first, last);
  const Objective objective(slab, metric);
  std::vector<int> b{0};
  for (int c : plan.boundaries)
    if (c > first && c < last) b.push_back(c - first);
  b.push_back(last - first);
  double sm = 0;
  for (std::size_t i = 0; i + 1 < b.size(); ++i) sm += objective.layer_sm(b[i], b[i + 1]);
  const double range = objective.e_coarse();
  if (!(range > 1e-12 * std::max(1.0, std::fabs(objective.sm_fine())))) return 1;  // nothing to lose here
  return std::clamp((sm - objective.sm_fine()) / range, 0.0, 1.0);
}

// Critical heights (paper §5 after [ZC95]): boundaries where neighbouring layers' thicknesses
// jump by more than `jump` mm.
void add_critical(const ZProfile& p, const LayerPlan& plan, double jump, std::vector<int>& out) {
  const auto& b = plan.boundaries;
  for (std::size_t i = 1; i + 1 < b.size(); ++i) {
    const double below = p.z(b[i]) - p.z(b[i - 1]), above = p.z(b[i + 1]) - p.z(b[i]);
    if (std::fabs(above - below) > jump + 1e-9) out.push_back(b[i]);
  }
}

// The exact planner restricted to the allowed cells: fewest layers within the budget.
std::optional<LayerPlan> exact_on_allowed(const Objective& objective, std::vector<char> allowed, double epsilon,
                                          const RunContext& run) {
  ExactSolver solver(objective, run);
  solver.restrict_boundaries(std::move(allowed));
  const ZProfile& p = objective.profile();
  const double budget = objective.sm_fine() + epsilon;
  const double slack = 1e-12 * std::max(1.0, std::fabs(budget));
  for (int n = p.fewest_layers(); n <= p.most_layers(); ++n)
    if (solver.best_sm(n) <= budget + slack) return solver.plan(n);
  return std::nullopt;
}

bool meets(const ZProfile& p, const PlanRegion& region, const PlanRegion& neighbour) {
  const std::vector<char> allowed = seam_allowed(p, region.first_cell, region.last_cell, neighbour);
  return std::all_of(region.plan.boundaries.begin(), region.plan.boundaries.end(),
                     [&](int b) { return allowed[b - region.first_cell] != 0; });
}

}  // namespace

std::array<double, 2> split_budget(const ZProfile& part0, const ZProfile& part1, Metric metric, double epsilon,
                                   double weight0, double weight1, const RunContext& run) {
  const Objective o0(part0, metric), o1(part1, metric);
  ExactSolver s0(o0, run), s1(o1, run);
  double best_cost = INFINITY, best_e0 = 0;
  for (int n0 = part0.fewest_layers(); n0 <= part0.most_layers(); ++n0) {
    const double e0 = std::max(0.0, s0.best_sm(n0) - o0.sm_fine());
    if (!(e0 <= epsilon)) continue;
    const int n1 = s1.fewest_layers_within(o1.sm_fine() + (epsilon - e0));
    const double cost = weight0 * n0 + weight1 * n1;
    if (cost < best_cost) best_cost = cost, best_e0 = e0;
  }
  return {best_e0, std::max(0.0, epsilon - best_e0)};
}

std::optional<PlanRegion> plan_region(const ZProfile& profile, int first, int last, int side, Polygon clip,
                                      std::optional<double> epsilon, const SegOptInput& in, const PlanRegion* neighbour,
                                      const RunContext& run) {
  const ZProfile slab = profile.window(first, last);
  const Objective objective(slab, in.metric);
  PlanRegion region;
  region.first_cell = first;
  region.last_cell = last;
  region.side = side;
  region.clip = std::move(clip);
  region.epsilon = epsilon ? *epsilon : objective.epsilon(in.rho);
  const PlanRequest request{objective, nullptr, nullptr, PlanTarget::within(region.epsilon), in.seed, run};
  LayerPlan local = in.planner.plan(request).plan;
  const auto to_whole = [&](const LayerPlan& plan) {
    PlanRegion r = region;
    r.plan.boundaries.clear();
    for (int b : plan.boundaries) r.plan.boundaries.push_back(b + first);
    return r;
  };
  region = to_whole(local);
  if (neighbour && !meets(profile, region, *neighbour)) {
    const auto constrained = exact_on_allowed(objective, seam_allowed(profile, first, last, *neighbour), region.epsilon, run);
    if (!constrained) return std::nullopt;
    local = *constrained;
    region = to_whole(local);
  }
  region.error = objective.error(local);
  return region;
}

SegOptResult seg_opt(const SegOptInput& in, const RegionTimer& seconds, const SegOptOptions& o, const RunContext& run) {
  const ZProfile& whole = in.profile;
  const int m = whole.cells();
  SegOptResult out;
  run.report("segment", 0);
  const auto single = plan_region(whole, 0, m, -1, {}, std::nullopt, in, nullptr, run);
  out.regions = {*single};
  out.whole_seconds = out.seconds = seconds(out.regions);

  out.seam = find_cut(in.mesh, in.saliency, o.seam, run);
  if (!out.seam) {
    out.note = "not cut: no vertical plane divides the model into parts of at least " +
               std::to_string(static_cast<int>(100 * o.seam.min_share)) + " % of its surface each";
    return out;
  }
  // Algorithm 1, line 1–2: both parts, each planned over the whole height.
  const CutPlane plane = out.seam->plane;
  const auto parts = split_mesh(in.mesh, in.saliency, plane);
  const BoundingBox box = bounding_box(in.mesh);
  const Point2 lo{box.min.x - 5, box.min.y - 5}, hi{box.max.x + 5, box.max.y + 5};
  const Polygon clip[2] = {half_plane(plane, 0, lo, hi), half_plane(plane, 1, lo, hi)};
  std::vector<ZProfile> profile;
  for (int s = 0; s < 2; ++s) profile.push_back(ZProfile::build(parts[s].mesh, parts[s].values, whole.params(), run, whole.height()));
  run.report("segment", 0.4);
  const auto budget = split_budget(profile[0], profile[1], in.metric, single->epsilon, parts[0].area, parts[1].area, run);
  std::vector<PlanRegion> halves;
  for (int s = 0; s < 2; ++s) halves.push_back(*plan_region(profile[s], 0, m, s, clip[s], budget[s], in, nullptr, run));
  out.parts_seconds = seconds(halves);  // T1 + T2, printed together as they will be
  out.parts = halves;
  const double ratio = out.parts_seconds / out.whole_seconds;
  if (!(ratio < o.tau)) {
    out.note = "not cut: the best plane's parts take " + std::to_string(static_cast<int>(std::lround(100 * ratio))) +
               " % of the whole's time (cut below " + std::to_string(static_cast<int>(std::lround(100 * o.tau))) + " %)";
    return out;
  }
  run.report("segment", 0.6);

  // Line 3: horizontal segmentation at the critical heights, merging where the parts are alike.
  std::vector<int> critical;
  for (int s = 0; s < 2; ++s) add_critical(profile[s], halves[s].plan, o.critical_jump, critical);
  std::sort(critical.begin(), critical.end());
  std::vector<int> cuts{0};
  for (int c : critical)
    if (c > cuts.back() && printable(whole, c - cuts.back()) && printable(whole, m - c)) cuts.push_back(c);
  cuts.push_back(m);
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    run.check();
    Slab slab{cuts[i], cuts[i + 1], false};
    for (int s = 0; s < 2; ++s) slab.loss[s] = relative_loss(profile[s], in.metric, halves[s].plan, slab.first_cell, slab.last_cell);
    slab.merged = std::fabs(slab.loss[0] - slab.loss[1]) < o.similar_loss;
    out.slabs.push_back(slab);
  }
  // Runs of alike slabs become one region (or one pair): the fewest seams.
  std::vector<PlanRegion> regions;
  bool any_cut = false;
  for (std::size_t i = 0; i < out.slabs.size();) {
    std::size_t j = i;
    double loss[2] = {0, 0};
    while (j < out.slabs.size() && out.slabs[j].merged == out.slabs[i].merged) {
      for (int s = 0; s < 2; ++s) loss[s] += out.slabs[j].loss[s] * (out.slabs[j].last_cell - out.slabs[j].first_cell);
      ++j;
    }
    const int first = out.slabs[i].first_cell, last = out.slabs[j - 1].last_cell;
    std::optional<PlanRegion> pair[2];
    if (!out.slabs[i].merged) {
      const int first_planned = loss[0] >= loss[1] ? 0 : 1;  // the coarser part
      const double eps = Objective(whole.window(first, last), in.metric).epsilon(in.rho);
      const auto share = split_budget(profile[0].window(first, last), profile[1].window(first, last), in.metric, eps,
                                      parts[0].area, parts[1].area, run);
      const int a = first_planned, b = 1 - first_planned;
      pair[a] = plan_region(profile[a], first, last, a, clip[a], share[a], in, nullptr, run);
      // The finer part gets what the coarser one left of the slab's budget (meeting the coarser
      // one's layers costs it some quality).
      pair[b] = plan_region(profile[b], first, last, b, clip[b], eps - pair[a]->error, in, &*pair[a], run);
    }
    if (pair[0] && pair[1]) {
      regions.push_back(std::move(*pair[0]));
      regions.push_back(std::move(*pair[1]));
      any_cut = true;
    } else {
      if (!out.slabs[i].merged)
        for (std::size_t k = i; k < j; ++k) out.slabs[k].merged = true;  // the parts could not meet
      regions.push_back(*plan_region(whole, first, last, -1, {}, std::nullopt, in, nullptr, run));
    }
    i = j;
  }
  // Neighbouring whole-section regions (after a failed pair) join into one.
  std::vector<PlanRegion> joined;
  for (PlanRegion& r : regions) {
    if (!joined.empty() && r.side < 0 && joined.back().side < 0) {
      joined.back() = *plan_region(whole, joined.back().first_cell, r.last_cell, -1, {}, std::nullopt, in, nullptr, run);
      continue;
    }
    joined.push_back(std::move(r));
  }
  run.report("segment", 0.8);
  if (!any_cut) {
    out.note = "not cut: the parts are sliced alike at every height, so every vertical seam was merged away";
    return out;
  }
  const double t = seconds(joined);
  if (!(t < out.whole_seconds)) {
    out.note = "not cut: once merged at its critical heights the cut no longer saves time";
    return out;
  }
  out.regions = std::move(joined);
  out.seconds = t;
  out.cut = true;
  int split = 0;
  for (const Slab& s : out.slabs) split += !s.merged;
  out.note = "cut: " + std::to_string(out.regions.size()) + " regions, " + std::to_string(split) + " of " +
             std::to_string(out.slabs.size()) + " slabs keep the vertical seam";
  run.report("segment", 1);
  return out;
}

}  // namespace salient::core
