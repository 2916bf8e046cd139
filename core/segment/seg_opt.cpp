// SegOpt. Choices the paper leaves open (ALGORITHMS.md §5):
// - Each part is profiled on the whole model's grid (its own faces, cut along the plane; the cut
//   face itself is inside the print and adds nothing), so the parts' layers can meet.
// - "Average SM" of a part within a slab is compared as its relative loss there: (SM of its plan
//   − SM of the slab's finest) / (SM of the slab's coarsest − finest), 0 where it is printed as
//   finely as possible and 1 where as coarsely; so the 0.03 threshold is on the scale of ρ.
// - Slabs must each be printable in layers of α..ᾱ: critical heights too close to the previous
//   one (or to the top) are dropped.
// - A slab's budget ε is shared by its parts through the exact E(n) curves (split_budget).
// - In a slab that keeps the cut, one part is planned first and the other must meet it
//   (PlanRegion's seam rule), with what the first left of ε; both orders are tried and the one
//   with fewer layers (weighted by area) kept. If neither fits ε, the slab is merged instead.
// - Recursion (depth > 1): each part of a cut slab is segmented again as a model of its own, its
//   budget over its E(coarse) as its ρ, its regions meeting every region they touch.
// - T1 + T2 is the parts printed together (merged by height), as they will be.
#include "core/segment/seg_opt.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

// A region of this level: `side` of this level's cut (-1: the part itself, uncut in that slab).
PlanRegion shape_of(const SegOptInput& in, int first, int last, int side, Polygon clip) {
  PlanRegion r;
  r.first_cell = first;
  r.last_cell = last;
  if (in.part) {
    r.side = in.part->side;
    r.sub = in.part->sub;
    if (side >= 0) r.sub.push_back(side);
    r.clip = side >= 0 ? std::move(clip) : in.part->clip;
  } else {
    r.side = side;
    r.clip = std::move(clip);
  }
  return r;
}

std::vector<const PlanRegion*> with(std::vector<const PlanRegion*> list, const PlanRegion* more) {
  list.push_back(more);
  return list;
}

// The whole section of [first, last) at this level, planned to ρ and meeting the neighbours.
std::optional<PlanRegion> uncut(const SegOptInput& in, int first, int last, const RunContext& run) {
  return plan_region(in.profile, shape_of(in, first, last, -1, {}), std::nullopt, in, in.neighbours, run);
}

// One plane tried: the model cut by it, both parts profiled on the whole grid and each planned
// over the full height with its share of the budget (Algorithm 1, lines 1–2), and T1 + T2.
struct Trial {
  std::array<MeshPart, 2> parts;
  Polygon clip[2];
  std::vector<ZProfile> profile;
  std::vector<PlanRegion> halves;
  double seconds = 0;
  SeamCandidate seam;
};

// Of the candidate planes, the one whose parts print fastest.
Trial choose_plane(const SegOptInput& in, const std::vector<SeamCandidate>& planes, const PlanRegion& single,
                   const RegionTimer& seconds, const RunContext& run) {
  const ZProfile& whole = in.profile;
  const int first_cell = single.first_cell, last_cell = single.last_cell;
  const BoundingBox box = bounding_box(in.mesh);
  const Polygon area = in.part && !in.part->clip.empty()
                           ? in.part->clip
                           : rectangle({box.min.x - 5, box.min.y - 5}, {box.max.x + 5, box.max.y + 5});
  std::optional<Trial> chosen;
  for (const SeamCandidate& candidate : planes) {
    Trial t{split_mesh(in.mesh, in.saliency, candidate.plane), {}, {}, {}, 0, candidate};
    for (int s = 0; s < 2; ++s) {
      t.clip[s] = half_plane(candidate.plane, s, area);
      t.profile.push_back(
          ZProfile::build(t.parts[s].mesh, t.parts[s].values, whole.params(), run, whole.height()));
    }
    const auto budget =
        split_budget(t.profile[0].window(first_cell, last_cell), t.profile[1].window(first_cell, last_cell),
                     in.metric, single.epsilon, t.parts[0].area, t.parts[1].area, run);
    for (int s = 0; s < 2; ++s)
      t.halves.push_back(*plan_region(t.profile[s], shape_of(in, first_cell, last_cell, s, t.clip[s]),
                                      budget[s], in, {}, run));
    t.seconds = seconds(t.halves);  // T1 + T2, printed together as they will be
    if (!chosen || t.seconds < chosen->seconds) chosen = std::move(t);
  }
  return std::move(*chosen);
}

// Line 3: the horizontal segmentation at the parts' critical heights; a slab is merged where the
// parts' relative losses are alike.
std::vector<Slab> slabs_of(const SegOptInput& in, const Trial& t, int first_cell, int last_cell,
                           const SegOptOptions& o, const RunContext& run) {
  std::vector<int> critical;
  for (int s = 0; s < 2; ++s) add_critical(t.profile[s], t.halves[s].plan, o.critical_jump, critical);
  std::sort(critical.begin(), critical.end());
  std::vector<int> cuts{first_cell};
  // The fixed first layer's top is no critical height: its jump to the layers above is the printer's.
  const int fixed_top = first_cell == 0 ? in.first_cells : 0;
  for (int c : critical)
    if (c > cuts.back() && c > fixed_top && printable(in.profile, c - cuts.back()) &&
        printable(in.profile, last_cell - c))
      cuts.push_back(c);
  cuts.push_back(last_cell);
  std::vector<Slab> slabs;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    run.check();
    Slab slab{cuts[i], cuts[i + 1], false};
    for (int s = 0; s < 2; ++s)
      slab.loss[s] =
          relative_loss(t.profile[s], in.metric, t.halves[s].plan, slab.first_cell, slab.last_cell);
    slab.merged = std::fabs(slab.loss[0] - slab.loss[1]) < o.similar_loss;
    slabs.push_back(slab);
  }
  return slabs;
}

// Both parts of a run of cut slabs [first, last), sharing its budget; `loss` the parts' losses
// there. One part is planned first, the other then meets its layers (and gets what the first left
// of the slab's budget). Which order costs less depends on the parts: a thin part inside a thick
// one's layers keeps most of its choices, unless it must keep exactly α layers; so both are
// tried, and the one with fewer layers (weighted by the parts' areas) is kept. Empty if neither fits.
std::optional<std::array<PlanRegion, 2>> plan_pair(const SegOptInput& in, const Trial& t, int first, int last,
                                                   const double (&loss)[2], const RunContext& run) {
  const double eps = Objective(in.profile.window(first, last), in.metric).epsilon(in.rho);
  const auto share = split_budget(t.profile[0].window(first, last), t.profile[1].window(first, last),
                                  in.metric, eps, t.parts[0].area, t.parts[1].area, run);
  std::optional<std::array<PlanRegion, 2>> pair;
  double best = INFINITY;
  for (int a : {loss[0] >= loss[1] ? 0 : 1, loss[0] >= loss[1] ? 1 : 0}) {
    const int b = 1 - a;
    const PlanRegion shape_b = shape_of(in, first, last, b, t.clip[b]);
    std::vector<const PlanRegion*> beside_b;  // what the second part must meet besides the first
    for (const PlanRegion* n : in.neighbours)
      if (touching(shape_b, *n)) beside_b.push_back(n);
    // If what is left is not enough for the second part, the first gives up more of its share.
    for (double give : {1.0, 0.5, 0.25}) {
      auto pa = plan_region(t.profile[a], shape_of(in, first, last, a, t.clip[a]), give * share[a], in,
                            in.neighbours, run, beside_b);
      if (!pa) continue;
      auto pb = plan_region(t.profile[b], shape_b, eps - pa->error, in, with(in.neighbours, &*pa), run);
      if (!pb) continue;
      const double cost = t.parts[a].area * pa->layers() + t.parts[b].area * pb->layers();
      if (cost < best) {
        best = cost;
        pair.emplace();
        (*pair)[a] = std::move(*pa), (*pair)[b] = std::move(*pb);
      }
      break;
    }
  }
  return pair;
}

struct SlabRegions {
  std::vector<PlanRegion> regions;
  bool any_cut = false;
  bool failed = false;  // a run of slabs could be planned neither cut nor whole
};

// Runs of alike slabs become one region (or one pair): the fewest seams. A cut run whose parts
// cannot meet is merged (and its slabs marked so).
SlabRegions plan_slabs(const SegOptInput& in, const Trial& t, std::vector<Slab>& slabs,
                       const RunContext& run) {
  SlabRegions out;
  for (std::size_t i = 0; i < slabs.size();) {
    std::size_t j = i;
    double loss[2] = {0, 0};
    while (j < slabs.size() && slabs[j].merged == slabs[i].merged) {
      for (int s = 0; s < 2; ++s) loss[s] += slabs[j].loss[s] * (slabs[j].last_cell - slabs[j].first_cell);
      ++j;
    }
    const int first = slabs[i].first_cell, last = slabs[j - 1].last_cell;
    std::optional<std::array<PlanRegion, 2>> pair;
    if (!slabs[i].merged) pair = plan_pair(in, t, first, last, loss, run);
    std::optional<PlanRegion> merged;
    if (!pair) merged = uncut(in, first, last, run);
    if (pair) {
      out.regions.push_back(std::move((*pair)[0]));
      out.regions.push_back(std::move((*pair)[1]));
      out.any_cut = true;
    } else if (merged) {
      if (!slabs[i].merged)
        for (std::size_t k = i; k < j; ++k) slabs[k].merged = true;  // the parts could not meet
      out.regions.push_back(std::move(*merged));
    } else {
      out.failed = true;
      return out;
    }
    i = j;
  }
  return out;
}

// Neighbouring uncut regions (after a failed pair) join into one.
std::vector<PlanRegion> join_uncut(const SegOptInput& in, std::vector<PlanRegion> regions,
                                   const RunContext& run) {
  std::vector<PlanRegion> joined;
  for (PlanRegion& r : regions) {
    const bool uncut_here = r.sub.size() == (in.part ? in.part->sub.size() : 0) && (in.part || r.side < 0);
    const bool after_uncut = !joined.empty() && joined.back().sub.size() == r.sub.size() &&
                             joined.back().side == r.side && joined.back().clip == r.clip;
    if (uncut_here && after_uncut) {
      if (auto j = uncut(in, joined.back().first_cell, r.last_cell, run)) {
        joined.back() = std::move(*j);
        continue;
      }
    }
    joined.push_back(std::move(r));
  }
  return joined;
}

// Algorithm 1, recursively: each cut part of `joined` cut again where that saves time. Returns
// how many regions that added.
int recurse(const SegOptInput& in, const Trial& t, std::vector<PlanRegion>& joined,
            const RegionTimer& seconds, const SegOptOptions& o, const RunContext& run) {
  int deeper = 0;
  SegOptOptions next = o;
  next.depth = o.depth - 1;
  for (std::size_t k = 0; k < joined.size(); ++k) {
    const PlanRegion r = joined[k];
    if (r.sub.size() != (in.part ? in.part->sub.size() + 1 : 0) || r.side < 0) continue;  // an uncut slab
    const int s = in.part ? r.sub.back() : r.side;
    const MeshPart slab =
        crop_z(t.parts[s].mesh, t.parts[s].values, in.profile.z(r.first_cell), in.profile.z(r.last_cell));
    // The part's budget becomes its own ρ, so its slabs share ε as the whole model's do.
    const double e_coarse = Objective(t.profile[s].window(r.first_cell, r.last_cell), in.metric).e_coarse();
    const double rho = e_coarse > 0 ? r.epsilon / e_coarse : in.rho;
    SegOptInput sub{slab.mesh, slab.values, t.profile[s], in.metric,     in.planner,
                    rho,       in.seed,     &r,           in.neighbours, in.first_cells};
    for (std::size_t q = 0; q < joined.size(); ++q)
      if (q != k) sub.neighbours.push_back(&joined[q]);
    const SegOptResult inner = seg_opt(sub, seconds, next, run);
    if (!inner.cut) continue;
    joined.erase(joined.begin() + static_cast<std::ptrdiff_t>(k));
    joined.insert(joined.begin() + static_cast<std::ptrdiff_t>(k), inner.regions.begin(),
                  inner.regions.end());
    k += inner.regions.size() - 1;
    deeper += static_cast<int>(inner.regions.size()) - 1;
  }
  return deeper;
}

}  // namespace

std::array<double, 2> split_budget(const ZProfile& part0, const ZProfile& part1, Metric metric,
                                   double epsilon, double weight0, double weight1, const RunContext& run) {
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

SegOptResult seg_opt(const SegOptInput& in, const RegionTimer& seconds, const SegOptOptions& o,
                     const RunContext& run) {
  const int first_cell = in.part ? in.part->first_cell : 0,
            last_cell = in.part ? in.part->last_cell : in.profile.cells();  // the part's own profile
  SegOptResult out;
  run.report("segment", 0);
  const std::optional<PlanRegion> single = in.part ? *in.part : uncut(in, first_cell, last_cell, run);
  if (!single) throw std::logic_error("seg_opt: a whole model always has a plan");
  out.regions = {*single};
  out.whole_seconds = out.seconds = seconds(out.regions);

  const std::vector<SeamCandidate> planes =
      find_cuts(in.mesh, in.saliency, std::max(1, o.planes), o.seam, run);
  if (planes.empty()) {
    out.note = "not cut: no vertical plane divides the model into parts of at least " +
               std::to_string(static_cast<int>(100 * o.seam.min_share)) + " % of its surface each";
    return out;
  }
  const Trial chosen = choose_plane(in, planes, *single, seconds, run);
  out.seam = chosen.seam;
  run.report("segment", 0.4);
  out.parts_seconds = chosen.seconds;
  out.parts = chosen.halves;
  const double ratio = out.parts_seconds / out.whole_seconds;
  if (!(ratio < o.tau)) {
    out.note = "not cut: the best plane's parts take " +
               std::to_string(static_cast<int>(std::lround(100 * ratio))) +
               " % of the whole's time (cut below " +
               std::to_string(static_cast<int>(std::lround(100 * o.tau))) + " %)";
    return out;
  }
  run.report("segment", 0.6);

  out.slabs = slabs_of(in, chosen, first_cell, last_cell, o, run);
  SlabRegions planned = plan_slabs(in, chosen, out.slabs, run);
  if (planned.failed) {
    out.note = "not cut: a slab of the part cannot meet its neighbours' layers within its budget";
    return out;
  }
  std::vector<PlanRegion> joined = join_uncut(in, std::move(planned.regions), run);
  run.report("segment", 0.8);
  if (!planned.any_cut) {
    out.note = "not cut: the parts are sliced alike at every height, so every vertical seam was merged away";
    return out;
  }
  const int deeper = o.depth > 1 ? recurse(in, chosen, joined, seconds, o, run) : 0;
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
  if (deeper > 0) out.note += ", " + std::to_string(deeper) + " more from cutting the parts again";
  run.report("segment", 1);
  return out;
}

}  // namespace salient::core
