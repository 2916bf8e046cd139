// SegOpt (paper §5, Algorithm 1; ALGORITHMS.md §5): cut the model by the best vertical plane,
// plan both parts, keep the cut only if it saves enough time ((T1 + T2)/T < τ), then cut both
// parts at their critical heights and merge them back in every slab where they would be sliced
// alike, so a vertical seam only remains where it saves time. The parts are printed as one object
// (merged by height), so T1 + T2 is estimated that way, not as two separate prints: a thin layer
// of one part still costs the nozzle a visit to that height, and short layers are slowed for
// cooling all the same.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"
#include "core/segment/plan_region.hpp"
#include "core/segment/seam_search.hpp"
#include "core/slicing/objective.hpp"
#include "core/slicing/planner.hpp"

namespace salient::core {

struct SegOptOptions {
  SeamOptions seam;
  double tau = 0.85;            // keep the cut if (T1 + T2)/T < τ
  double critical_jump = 0.05;  // mm: neighbouring layers differing more make a critical height
  double similar_loss = 0.03;   // merge a slab where the parts' relative losses differ less
  int depth = 1;   // levels of cutting: 2 and more cut each part again (Algorithm 1, recursively)
  int planes = 1;  // planes whose parts are planned and timed, best f(C) first (the paper: 1)
};

struct SegOptInput {
  const Mesh& mesh;                 // placed
  std::span<const float> saliency;  // per vertex
  const ZProfile& profile;          // of the whole model
  Metric metric = Metric::area;
  const Planner& planner;  // any planner that needs only the objective (not ha13)
  double rho = 0.05;       // a slab's ε = ρ · its E(coarse), shared by its parts (split_budget)
  std::uint64_t seed = 1;
  // A part of an already cut model (recursive SegOpt; the defaults are the whole model): its
  // region (slab, side, clip, plan and budget: `mesh` and `profile` are the part's, `rho` its
  // budget over its E(coarse)), and the regions beside it whose layers its own must meet.
  const PlanRegion* part = nullptr;
  std::vector<const PlanRegion*> neighbours;
  // The printer's fixed first layer, in cells (0: free): every region that starts on the bed
  // starts with it (core/slicing/planners/first_layer_planner), as an unsegmented plan does.
  int first_cells = 0;
};

// Estimated printing time (s) of a set of regions printed as one object.
using RegionTimer = std::function<double(const std::vector<PlanRegion>&)>;

struct Slab {
  int first_cell, last_cell;
  bool merged;              // one region across the cut
  double loss[2] = {0, 0};  // each part's relative loss there (RSMD of its plan within the slab)
};

struct SegOptResult {
  std::vector<PlanRegion> regions;  // a single whole region when the model is not cut
  bool cut = false;
  std::optional<SeamCandidate>
      seam;                       // the plane chosen (the fastest parts of those timed), whether kept or not
  std::vector<PlanRegion> parts;  // both parts over the full height (T1 + T2), when cut
  std::vector<Slab> slabs;        // the horizontal segmentation, when it was reached
  double whole_seconds = 0;       // T: the whole model with one plan
  double parts_seconds = 0;       // T1 + T2: each part planned over the full height, printed together
  double seconds = 0;             // the result's
  std::string note;               // what was decided and why
};

// Throws Cancelled when run.cancel fires. Progress: phase "segment".
SegOptResult seg_opt(const SegOptInput& input, const RegionTimer& seconds, const SegOptOptions& options = {},
                     const RunContext& run = {});

// The two parts of a slab share its budget ε: the split with the least Σ w_s·n_s such that
// Σ E_s(n_s) ≤ ε, n_s the layers of part s's best plan (exact) and w_s its weight (surface area,
// for the time a layer of it takes). A part with little saliency takes the budget to go coarse
// instead of being held to the same relative loss as the salient one. Returns {ε_0, ε_1}.
std::array<double, 2> split_budget(const ZProfile& part0, const ZProfile& part1, Metric metric,
                                   double epsilon, double weight0, double weight1,
                                   const RunContext& run = {});

}  // namespace salient::core
