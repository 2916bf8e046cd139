// ExactSolver: the global optimum of problem (4) on the grid, by dynamic programming
// (ALGORITHMS.md §4): f[n][j] = min over α ≤ z_j − z_i ≤ ᾱ of f[n−1][i] + SM(i, j).
#pragma once

#include <cstdint>
#include <vector>

#include "core/common/progress.hpp"
#include "core/slicing/objective.hpp"

namespace salient::core {

class ExactSolver {
 public:
  explicit ExactSolver(const Objective& objective, const RunContext& run = {});

  // Boundaries only on cells k with allowed[k] (size cells() + 1; 0 and M are always allowed):
  // a region of a segmented plan that must meet its neighbour's layers. Call before any query.
  void restrict_boundaries(std::vector<char> allowed);

  // Least SM of any plan with exactly n layers (infinity if none exists).
  double best_sm(int n);
  // The plan achieving best_sm(n); requires a feasible n.
  LayerPlan plan(int n);
  // Fewest layers whose best plan has SM ≤ sm_budget (most_layers() if none does).
  int fewest_layers_within(double sm_budget);

 private:
  void compute_rows_up_to(int n);
  template <Metric M>
  void compute_row();

  const Objective& objective_;
  RunContext run_;
  std::vector<double> prev_, cur_;                // f[n−1][*], f[n][*]
  std::vector<char> allowed_;                     // empty: every cell
  std::vector<double> final_;                     // f[n][M] for every computed n (index n)
  std::vector<std::vector<std::uint16_t>> back_;  // back_[n][j] = width of the last layer
  int rows_ = 0;
};

}  // namespace salient::core
