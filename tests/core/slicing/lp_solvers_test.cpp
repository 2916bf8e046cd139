// The AdapSlice LPs solved by our dedicated solvers match GLPK's simplex on random instances.
#include "core/slicing/lp_solvers.hpp"

#include <doctest/doctest.h>
#include <glpk.h>

#include <numeric>
#include <random>

using namespace salient::core;

namespace {

// min c·x  s.t. lo ≤ x ≤ hi, Σx = total, and (if g) g·x ≤ budget. Returns the optimum or NaN.
double glpk_solve(const std::vector<double>& c, const std::vector<double>& lo, const std::vector<double>& hi,
                  double total, const std::vector<double>* g, double budget) {
  glp_prob* lp = glp_create_prob();
  glp_set_obj_dir(lp, GLP_MIN);
  const int n = static_cast<int>(c.size());
  glp_add_cols(lp, n);
  for (int j = 1; j <= n; ++j) {
    glp_set_col_bnds(lp, j, lo[j - 1] == hi[j - 1] ? GLP_FX : GLP_DB, lo[j - 1], hi[j - 1]);
    glp_set_obj_coef(lp, j, c[j - 1]);
  }
  const int rows = g ? 2 : 1;
  glp_add_rows(lp, rows);
  glp_set_row_bnds(lp, 1, GLP_FX, total, total);
  if (g) glp_set_row_bnds(lp, 2, GLP_UP, 0, budget);
  std::vector<int> ia(1), ja(1);
  std::vector<double> ar(1);
  for (int j = 1; j <= n; ++j) {
    ia.push_back(1), ja.push_back(j), ar.push_back(1);
    if (g) ia.push_back(2), ja.push_back(j), ar.push_back((*g)[j - 1]);
  }
  glp_load_matrix(lp, static_cast<int>(ia.size()) - 1, ia.data(), ja.data(), ar.data());
  glp_smcp params;
  glp_init_smcp(&params);
  params.msg_lev = GLP_MSG_OFF;
  glp_simplex(lp, &params);
  const double value = glp_get_status(lp) == GLP_OPT ? glp_get_obj_val(lp) : std::nan("");
  glp_delete_prob(lp);
  return value;
}

}  // namespace

TEST_CASE("VisualOpt LP matches GLPK") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = std::uniform_int_distribution<int>(1, 60)(rng);
    std::vector<double> g(n);
    std::vector<int> lo(n), hi(n);
    for (int i = 0; i < n; ++i) {
      g[i] = std::uniform_real_distribution<double>(0, 5)(rng);
      lo[i] = std::uniform_int_distribution<int>(5, 12)(rng);
      hi[i] = lo[i] + std::uniform_int_distribution<int>(0, 30)(rng);
    }
    const int total = std::uniform_int_distribution<int>(std::accumulate(lo.begin(), lo.end(), 0),
                                                         std::accumulate(hi.begin(), hi.end(), 0))(rng);
    const auto x = solve_visual_lp(g, lo, hi, total);
    REQUIRE(x);
    CHECK(std::accumulate(x->begin(), x->end(), 0) == total);
    double ours = 0;
    for (int i = 0; i < n; ++i) {
      CHECK(((*x)[i] >= lo[i] && (*x)[i] <= hi[i]));
      ours += g[i] * (*x)[i];
    }
    const double theirs = glpk_solve(g, std::vector<double>(lo.begin(), lo.end()),
                                     std::vector<double>(hi.begin(), hi.end()), total, nullptr, 0);
    CHECK(ours == doctest::Approx(theirs).epsilon(1e-9));
  }
  CHECK_FALSE(solve_visual_lp({1, 1}, {5, 5}, {6, 6}, 20).has_value());
}

TEST_CASE("TimeOpt LP matches GLPK, including when the budget binds") {
  std::mt19937 rng(5);
  int binding = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const int n = std::uniform_int_distribution<int>(2, 80)(rng);
    std::vector<double> c(n), g(n), u(n);
    for (int i = 0; i < n; ++i) {
      // weights like eq. 7: some huge (layers at α), most moderate
      c[i] = std::uniform_int_distribution<int>(0, 4)(rng) == 0
                 ? 1e8
                 : std::uniform_real_distribution<double>(2, 40)(rng);
      g[i] = std::uniform_real_distribution<double>(0.01, 3)(rng);
      u[i] = std::uniform_int_distribution<int>(10, 40)(rng);
    }
    const double cap = std::accumulate(u.begin(), u.end(), 0.0);
    const double total = std::uniform_real_distribution<double>(0.3, 0.9)(rng) * cap;
    // A budget between the least and the greatest g·x a fill can reach, so it often binds.
    std::vector<double> zeros(n, 0.0);
    const double budget = std::uniform_real_distribution<double>(0.0, 2.0)(rng) * total;
    const TimeLpSolution ours = solve_time_lp(c, g, u, total, budget);
    const double theirs = glpk_solve(c, zeros, u, total, &g, budget);
    CAPTURE(trial);
    if (std::isnan(theirs)) {
      CHECK_FALSE(ours.feasible);
      continue;
    }
    REQUIRE(ours.feasible);
    double sum = 0, gx = 0;
    for (int i = 0; i < n; ++i) {
      CHECK(ours.x[i] >= -1e-9);
      CHECK(ours.x[i] <= u[i] + 1e-9);
      sum += ours.x[i];
      gx += g[i] * ours.x[i];
    }
    CHECK(sum == doctest::Approx(total).epsilon(1e-9));
    CHECK(gx <= budget * (1 + 1e-9) + 1e-9);
    if (gx > budget * (1 - 1e-6)) ++binding;
    CHECK(ours.objective == doctest::Approx(theirs).epsilon(1e-7));
  }
  CHECK(binding > 10);
}
