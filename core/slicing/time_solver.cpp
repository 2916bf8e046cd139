// fastest_within. Every candidate layer's time and SM are tabulated once (M × W of each); each
// λ is then one pass over the grid. SM(λ) of the minimiser falls as λ grows, so bisection
// between an infeasible λ (0 unless the fastest plan already fits) and a feasible one converges
// on the fastest plan within the budget on the lower convex hull, and gives the dual bound.
// The hull may miss the optimum (a plan inside the hull's gap), so a label-setting search over
// the grid then closes the gap exactly: labels (time, SM) per boundary, kept only if no other
// label there is both faster and lower in SM, and only while they can still beat the incumbent
// — by three completion bounds from backward passes: least time, least SM and least
// t + λ·SM to the top (a plan through the label within the budget costs at least
// t + λ·s + L(j) − λ·budget). Bounded in labels; past the bound the hull plan stands, not proven.
#include "core/slicing/time_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace salient::core {
namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

struct Tables {
  int m = 0, wmin = 1, wmax = 1, width = 1;
  std::vector<double> t, sm;  // [j · width + (w − wmin)]
};

struct Path {
  LayerPlan plan;
  double value = inf, seconds = 0, sm = 0;  // value: Σ t + λ·SM
};

Path shortest(const Tables& tab, double lambda, std::vector<double>& g, std::vector<int>& back) {
  g.assign(tab.m + 1, inf);
  back.assign(tab.m + 1, 0);
  g[0] = 0;
  for (int j = tab.wmin; j <= tab.m; ++j) {
    const double* t = &tab.t[static_cast<std::size_t>(j) * tab.width];
    const double* s = &tab.sm[static_cast<std::size_t>(j) * tab.width];
    double best = inf;
    int best_w = 0;
    for (int w = tab.wmin, top = std::min(tab.wmax, j); w <= top; ++w) {
      const double f = g[j - w] + t[w - tab.wmin] + lambda * s[w - tab.wmin];
      if (f < best) best = f, best_w = w;
    }
    g[j] = best;
    back[j] = best_w;
  }
  Path p;
  p.value = g[tab.m];
  if (p.value == inf) return p;
  std::vector<int> widths;
  for (int j = tab.m; j > 0; j -= back[j]) {
    const int w = back[j];
    widths.push_back(w);
    p.seconds += tab.t[static_cast<std::size_t>(j) * tab.width + (w - tab.wmin)];
    p.sm += tab.sm[static_cast<std::size_t>(j) * tab.width + (w - tab.wmin)];
  }
  std::reverse(widths.begin(), widths.end());
  p.plan = plan_from_widths(widths);
  return p;
}

// Least cost from each boundary j to the top, cost = a·t + b·SM of the layers.
std::vector<double> completion(const Tables& tab, double a, double b) {
  std::vector<double> c(tab.m + 1, inf);
  c[tab.m] = 0;
  for (int i = tab.m - 1; i >= 0; --i)
    for (int w = tab.wmin; w <= tab.wmax && i + w <= tab.m; ++w) {
      const std::size_t at = static_cast<std::size_t>(i + w) * tab.width + (w - tab.wmin);
      c[i] = std::min(c[i], c[i + w] + a * tab.t[at] + b * tab.sm[at]);
    }
  return c;
}

struct Label {
  double t, s;
  int parent;  // index into the label store; −1 at the bed
  int node;
};

// The exact optimum by label setting (see the file comment), or `out` unchanged when the
// incumbent is already optimal or the labels exceed the bound.
void close_gap(const Tables& tab, double budget, double lambda, TimedPlan& out, const RunContext& run) {
  constexpr std::size_t max_labels = 3'000'000;
  const double tolerance = 1e-9 * std::max(1.0, out.seconds);
  if (out.seconds - out.lower_bound <= tolerance) {
    out.proven_optimal = true;
    return;
  }
  const std::vector<double> t_min = completion(tab, 1, 0), s_min = completion(tab, 0, 1),
                            l_min = completion(tab, 1, lambda);
  double incumbent = out.seconds;
  std::vector<Label> store;
  std::vector<std::vector<int>> at(tab.m + 1);  // labels waiting at each boundary
  store.push_back({0, 0, -1, 0});
  at[0].push_back(0);
  int best = -1;
  for (int j = 0; j <= tab.m; ++j) {
    if (j % 256 == 0) run.check();
    std::vector<int>& here = at[j];
    if (here.empty()) continue;
    // Pareto filter: by time, keep a label only if its SM is below every faster one's.
    std::sort(here.begin(), here.end(), [&](int a, int b) {
      return store[a].t < store[b].t || (store[a].t == store[b].t && store[a].s < store[b].s);
    });
    std::vector<int> kept;
    double s_floor = inf;
    for (int id : here)
      if (store[id].s < s_floor) kept.push_back(id), s_floor = store[id].s;
    std::vector<int>().swap(here);
    if (j == tab.m) {
      for (int id : kept)
        if (store[id].s <= budget && store[id].t < incumbent - tolerance) incumbent = store[id].t, best = id;
      break;
    }
    for (int id : kept) {
      const Label l = store[id];
      for (int w = tab.wmin; w <= tab.wmax && j + w <= tab.m; ++w) {
        const int k = j + w;
        const std::size_t cell = static_cast<std::size_t>(k) * tab.width + (w - tab.wmin);
        const double t = l.t + tab.t[cell], s = l.s + tab.sm[cell];
        if (s + s_min[k] > budget || t + t_min[k] >= incumbent - tolerance) continue;
        if (t + lambda * s + l_min[k] - lambda * budget >= incumbent - tolerance) continue;
        if (store.size() >= max_labels) return;  // too many to settle: the hull plan stands
        store.push_back({t, s, id, k});
        at[k].push_back(static_cast<int>(store.size() - 1));
      }
    }
  }
  out.proven_optimal = true;
  out.lower_bound = incumbent;
  if (best < 0) return;  // the hull plan was optimal
  std::vector<int> widths;
  for (int id = best; store[id].parent >= 0; id = store[id].parent)
    widths.push_back(store[id].node - store[store[id].parent].node);
  std::reverse(widths.begin(), widths.end());
  out.plan = plan_from_widths(widths);
  out.seconds = store[best].t;
  out.sm = store[best].s;
}

}  // namespace

TimedPlan fastest_within(const Objective& objective, const LayerTimeModel& time, double sm_budget,
                         const RunContext& run) {
  const ZProfile& profile = objective.profile();
  Tables tab;
  tab.m = profile.cells();
  tab.wmin = profile.min_cells();
  tab.wmax = profile.max_cells();
  tab.width = tab.wmax - tab.wmin + 1;
  const std::size_t size = static_cast<std::size_t>(tab.m + 1) * tab.width;
  tab.t.assign(size, inf);
  tab.sm.assign(size, 0);
  for (int j = tab.wmin; j <= tab.m; ++j) {
    if (j % 1024 == 0) run.check();
    for (int w = tab.wmin, top = std::min(tab.wmax, j); w <= top; ++w) {
      const std::size_t at = static_cast<std::size_t>(j) * tab.width + (w - tab.wmin);
      tab.t[at] = time.layer_seconds(j - w, j);
      tab.sm[at] = objective.layer_sm(j - w, j);
    }
  }
  const double slack = 1e-12 * std::max(1.0, std::abs(sm_budget));
  std::vector<double> g;
  std::vector<int> back;
  TimedPlan out;
  out.lower_bound = -inf;
  double best_lambda = 0;
  Path least_sm;  // the minimiser at the largest λ tried: the fallback when nothing fits
  auto consider = [&](double lambda) {
    Path p = shortest(tab, lambda, g, back);
    if (p.value == inf) return false;
    if (p.value - lambda * sm_budget > out.lower_bound) {
      out.lower_bound = p.value - lambda * sm_budget;
      best_lambda = lambda;
    }
    const bool fits = p.sm <= sm_budget + slack;
    if (fits && (!out.feasible || p.seconds < out.seconds)) {
      out.plan = p.plan;
      out.seconds = p.seconds;
      out.sm = p.sm;
      out.feasible = true;
    }
    if (!fits) least_sm = std::move(p);
    return fits;
  };
  if (!consider(0)) {
    double lo = 0, hi = 1e-3;
    bool found = false;
    for (int k = 0; k < 80 && !found; ++k) {
      run.check();
      if (consider(hi))
        found = true;
      else
        lo = hi, hi *= 4;
    }
    for (int it = 0; found && it < 64 && hi - lo > 1e-12 * hi; ++it) {
      run.check();
      const double mid = 0.5 * (lo + hi);
      if (consider(mid))
        hi = mid;
      else
        lo = mid;
    }
    if (!out.feasible && least_sm.value != inf) {
      out.plan = least_sm.plan;
      out.seconds = least_sm.seconds;
      out.sm = least_sm.sm;
    }
  }
  if (out.feasible) {
    out.lower_bound = std::min(out.lower_bound, out.seconds);
    close_gap(tab, sm_budget + slack, best_lambda, out, run);
  }
  run.report("exact", 1.0);
  return out;
}

}  // namespace salient::core
