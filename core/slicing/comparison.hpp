// The paper's Table 1 for one model: every planner at the same layer count as `exact` at ρ
// (RSMD, lower is better) and at the same loss (layers, fewer is better), plus adapslice's
// per-step trace (Fig. 10).
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/slicing/planner.hpp"

namespace salient::core {

struct ComparisonRow {
  std::string planner;
  int layers_at_count = 0;  // what it reached when asked for the reference count
  double rsmd_at_count = 0;
  int layers_at_rsmd = 0;  // fewest layers it needs for E ≤ E(reference)
  double rsmd_at_rsmd = 0;
  double seconds = 0;  // both runs
  std::string note;
};

struct Comparison {
  double rho = 0;
  double epsilon = 0;
  int reference_layers = 0;  // exact at ρ
  double reference_rsmd = 0;
  int fine_layers = 0, coarse_layers = 0;
  std::vector<ComparisonRow> rows;
  std::vector<PlanStep> adapslice_trace;  // at ρ
};

// `base` gives the objective, mesh, geometric objective, seed and run context; its target is
// ignored.
Comparison compare_planners(const PlanRequest& base, double rho, std::span<const std::string_view> planners);

// The same table around a plan made elsewhere (`given`, on the profile's grid) instead of `exact`
// at ρ: its row first, named `label`, then every planner at its layer count and at its loss.
// Where its count is outside what α..ᾱ allow, the planners run at the nearest count they can.
// reference_layers and reference_rsmd are the given plan's; rho and epsilon stay 0.
Comparison compare_with_plan(const PlanRequest& base, const LayerPlan& given, const std::string& label,
                             std::span<const std::string_view> planners);

}  // namespace salient::core
