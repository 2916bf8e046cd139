// ExactSolver. Rows are computed on demand and kept (back-pointers as 16-bit widths), so
// asking for the fewest layers within a budget costs only the rows up to the answer.
// Row n only visits j in [n·α/δ, min(M, n·ᾱ/δ)]; the paper metric's range maxima are kept
// as running maxima while the last layer widens, so each transition is O(1).
#include "core/slicing/exact_solver.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace salient::core {
namespace {
constexpr double inf = std::numeric_limits<double>::infinity();
}

ExactSolver::ExactSolver(const Objective& objective, const RunContext& run)
    : objective_(objective), run_(run) {
  const int m = objective.profile().cells();
  prev_.assign(m + 1, inf);
  cur_.assign(m + 1, inf);
  cur_[0] = 0;  // row 0: nothing printed
  final_.push_back(m == 0 ? 0 : inf);
  back_.emplace_back();
}

template <Metric M>
void ExactSolver::compute_row() {
  const ZProfile& p = objective_.profile();
  const int m = p.cells(), wmin = p.min_cells(), wmax = p.max_cells();
  const int n = rows_ + 1;
  std::swap(prev_, cur_);
  std::fill(cur_.begin(), cur_.end(), inf);
  std::vector<std::uint16_t> back(m + 1, 0);
  const ProfileChannel& ch = p.channel(objective_.geometric());
  const auto& S = ch.S;
  const auto& C = p.cos_theta();
  const auto& P = ch.A_prefix;
  const long long lo = static_cast<long long>(n) * wmin;
  const int j_lo = static_cast<int>(std::min<long long>(lo, m + 1));
  const int j_hi = static_cast<int>(std::min<long long>(static_cast<long long>(n) * wmax, m));
  for (int j = j_lo; j <= j_hi; ++j) {
    if (!allowed_.empty() && j < m && !allowed_[j]) continue;
    double best = inf;
    int best_w = 0;
    float s_max = 0, c_max = 0;
    const double zj = p.z(j);
    const int w_top = std::min(wmax, j - (n - 1) * wmin);
    for (int w = M == Metric::paper ? 1 : wmin; w <= w_top; ++w) {
      const int i = j - w;
      if constexpr (M == Metric::paper) {
        s_max = std::max(s_max, S[i]);
        c_max = std::max(c_max, C[i]);
      }
      if (w < wmin || prev_[i] == inf) continue;
      const double h = zj - p.z(i);
      double cost;
      if constexpr (M == Metric::area)
        cost = 0.5 * h * (P[j] - P[i]);
      else
        cost = h * s_max * c_max;
      const double f = prev_[i] + cost;
      if (f < best) {
        best = f;
        best_w = w;
      }
    }
    cur_[j] = best;
    back[j] = static_cast<std::uint16_t>(best_w);
  }
  back_.push_back(std::move(back));
  final_.push_back(cur_[m]);
  rows_ = n;
}

void ExactSolver::restrict_boundaries(std::vector<char> allowed) {
  if (rows_ > 0) throw std::logic_error("ExactSolver::restrict_boundaries after the first query");
  if (allowed.size() != static_cast<std::size_t>(objective_.profile().cells()) + 1)
    throw std::invalid_argument("ExactSolver::restrict_boundaries: one flag per boundary cell");
  allowed_ = std::move(allowed);
}

void ExactSolver::compute_rows_up_to(int n) {
  const int most = objective_.profile().most_layers();
  n = std::min(n, most);
  while (rows_ < n) {
    run_.check();
    if (objective_.metric() == Metric::area)
      compute_row<Metric::area>();
    else
      compute_row<Metric::paper>();
    run_.report("exact", static_cast<double>(rows_) / most);
  }
}

double ExactSolver::best_sm(int n) {
  if (n < 1 || n > objective_.profile().most_layers()) return inf;
  compute_rows_up_to(n);
  return final_[n];
}

LayerPlan ExactSolver::plan(int n) {
  if (best_sm(n) == inf)
    throw std::invalid_argument("ExactSolver::plan: no plan with " + std::to_string(n) + " layers");
  LayerPlan plan;
  plan.boundaries.resize(n + 1);
  int j = objective_.profile().cells();
  for (int row = n; row >= 1; --row) {
    plan.boundaries[row] = j;
    j -= back_[row][j];
  }
  plan.boundaries[0] = j;
  return plan;
}

int ExactSolver::fewest_layers_within(double sm_budget) {
  const ZProfile& p = objective_.profile();
  // Tolerance for rounding: sums of the same terms in another order.
  const double slack = 1e-12 * std::max(1.0, std::abs(sm_budget));
  for (int n = p.fewest_layers(); n <= p.most_layers(); ++n)
    if (best_sm(n) <= sm_budget + slack) return n;
  return p.most_layers();
}

}  // namespace salient::core
