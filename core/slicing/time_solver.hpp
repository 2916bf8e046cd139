// fastest_within: the plan of least estimated printing time whose SM stays within a budget
// (E ≤ ε), the `time` objective of `exact` (ALGORITHMS.md §4). A resource-constrained shortest
// path on the grid: Lagrangian relaxation first (for a multiplier λ ≥ 0 the plan minimising
// Σ t(layer) + λ·SM(layer) is one shortest path, O(M·W); bisection on λ finds the fastest such
// plan within the budget, and min over plans of T + λ(SM − budget) bounds the optimum from
// below), then an exact label-setting search inside the remaining gap.
#pragma once

#include "core/common/progress.hpp"
#include "core/slicing/layer_time_model.hpp"
#include "core/slicing/objective.hpp"

namespace salient::core {

struct TimedPlan {
  LayerPlan plan;
  double seconds = 0;           // the model's time of `plan`
  double sm = 0;                // its SM
  double lower_bound = 0;       // no plan within the budget is faster than this (Lagrangian dual), s
  bool feasible = false;        // false: no plan meets the budget; `plan` is the one of least SM found
  bool proven_optimal = false;  // the gap was closed: `plan` is the fastest on the grid
};

// `time` must cover the same cells as `objective`'s profile.
TimedPlan fastest_within(const Objective& objective, const LayerTimeModel& time, double sm_budget,
                         const RunContext& run = {});

}  // namespace salient::core
