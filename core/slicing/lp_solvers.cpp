// LP solvers for AdapSlice.
#include "core/slicing/lp_solvers.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace salient::core {

std::optional<std::vector<int>> solve_visual_lp(const std::vector<double>& g, const std::vector<int>& lo,
                                                const std::vector<int>& hi, int total) {
  long long sum_lo = 0, sum_hi = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (lo[i] > hi[i]) return std::nullopt;
    sum_lo += lo[i];
    sum_hi += hi[i];
  }
  if (sum_lo > total || sum_hi < total) return std::nullopt;
  std::vector<int> x = lo;
  long long left = total - sum_lo;
  std::vector<std::size_t> order(g.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return g[a] < g[b]; });
  for (std::size_t i : order) {
    if (left == 0) break;
    const long long add = std::min<long long>(left, hi[i] - lo[i]);
    x[i] += static_cast<int>(add);
    left -= add;
  }
  return x;
}

namespace {

// Fill `total` into boxes [0, u] in ascending order of c + λ·g (ties: smaller g first).
std::vector<double> fill(const std::vector<double>& c, const std::vector<double>& g,
                         const std::vector<double>& u, double total, double lambda, bool by_g_only) {
  std::vector<std::size_t> order(c.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double ka = by_g_only ? g[a] : c[a] + lambda * g[a];
    const double kb = by_g_only ? g[b] : c[b] + lambda * g[b];
    if (ka != kb) return ka < kb;
    if (g[a] != g[b]) return g[a] < g[b];
    return c[a] < c[b];
  });
  std::vector<double> x(c.size(), 0);
  double left = total;
  for (std::size_t i : order) {
    if (left <= 0) break;
    x[i] = std::min(u[i], left);
    left -= x[i];
  }
  return x;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  return std::inner_product(a.begin(), a.end(), b.begin(), 0.0);
}

}  // namespace

TimeLpSolution solve_time_lp(const std::vector<double>& c, const std::vector<double>& g,
                             const std::vector<double>& u, double total, double budget) {
  TimeLpSolution s;
  if (std::accumulate(u.begin(), u.end(), 0.0) < total) return s;
  const double tol = 1e-12 * std::max(1.0, std::abs(budget));
  std::vector<double> x = fill(c, g, u, total, 0, false);
  if (dot(g, x) <= budget + tol) {
    s.x = std::move(x);
    s.objective = dot(c, s.x);
    s.feasible = true;
    return s;
  }
  const std::vector<double> least = fill(c, g, u, total, 0, true);
  if (dot(g, least) > budget + tol) {
    s.x = least;
    s.objective = dot(c, s.x);
    return s;
  }
  double lo = 0, hi = 1;
  std::vector<double> x_hi = fill(c, g, u, total, hi, false);
  for (int i = 0; i < 2100 && dot(g, x_hi) > budget + tol; ++i) {
    lo = hi;
    hi *= 2;
    x_hi = fill(c, g, u, total, hi, false);
  }
  if (dot(g, x_hi) > budget + tol) x_hi = least;  // λ beyond any double: order by g alone
  std::vector<double> x_lo = fill(c, g, u, total, lo, false);
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    std::vector<double> xm = fill(c, g, u, total, mid, false);
    if (dot(g, xm) > budget + tol) {
      lo = mid;
      x_lo = std::move(xm);
    } else {
      hi = mid;
      x_hi = std::move(xm);
    }
  }
  const double g_lo = dot(g, x_lo), g_hi = dot(g, x_hi);
  const double theta = g_lo > g_hi ? std::clamp((budget - g_hi) / (g_lo - g_hi), 0.0, 1.0) : 0.0;
  s.x.resize(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) s.x[i] = theta * x_lo[i] + (1 - theta) * x_hi[i];
  s.objective = dot(c, s.x);
  s.feasible = true;
  return s;
}

}  // namespace salient::core
