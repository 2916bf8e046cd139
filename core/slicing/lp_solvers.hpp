// Exact solvers for the paper's two linear programs once each layer's cost per unit height is
// frozen at the current plan (paper §4, eqs. 6 and 9; ALGORITHMS.md §4 "adapslice").
#pragma once

#include <optional>
#include <vector>

namespace salient::core {

// VisualOpt (eq. 9): minimise Σ g_i·x_i subject to lo_i ≤ x_i ≤ hi_i and Σ x_i = total, over
// integers (grid cells). A box and one equality: filling the cheapest first is optimal.
// nullopt if Σ lo > total or Σ hi < total.
std::optional<std::vector<int>> solve_visual_lp(const std::vector<double>& g, const std::vector<int>& lo,
                                                const std::vector<int>& hi, int total);

struct TimeLpSolution {
  std::vector<double> x;
  double objective = 0;
  bool feasible = false;
};

// TimeOpt (eq. 6, the weighted-ℓ1 relaxation): minimise Σ c_i·x_i subject to 0 ≤ x_i ≤ u_i,
// Σ x_i = total and Σ g_i·x_i ≤ budget, over reals. Solved through its Lagrangian in the one
// inequality: for a multiplier λ ≥ 0 the box-and-sum problem is solved by filling in order of
// c_i + λ·g_i; λ* is bracketed by bisection and the two fills at its ends are blended so the
// budget holds with equality — an optimal vertex of the LP. Infeasible (feasible = false,
// x the least-Σg fill) if even Σ g_i·x_i at its minimum exceeds the budget.
TimeLpSolution solve_time_lp(const std::vector<double>& c, const std::vector<double>& g,
                             const std::vector<double>& u, double total, double budget);

}  // namespace salient::core
