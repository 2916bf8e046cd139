// given_plan: snapping to the grid, and the checks that the plan is one for this model.
#include "core/slicing/given_plan.hpp"

#include <cmath>
#include <cstdio>

#include "core/common/input_error.hpp"
#include "core/slicing/z_profile.hpp"

namespace salient::core {
namespace {

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f mm", v);
  return buf;
}

}  // namespace

GivenPlan given_plan(const ZProfile& profile, const std::vector<double>& tops,
                     const std::vector<std::uint64_t>& lines, const std::string& name) {
  const auto where = [&](std::size_t i) {
    return i < lines.size() && lines[i] > 0 ? InputLocation::at_line(lines[i]) : InputLocation{};
  };
  const double h = profile.height(), grid = profile.grid(), slack = profile.max_cells() * grid;
  if (tops.empty()) throw InputError(name, {}, "has no layers");
  GivenPlan out;
  out.top = tops.back();
  if (tops.back() < h - slack - 1e-9)
    throw InputError(name, where(tops.size() - 1),
                     "layers end at " + mm(tops.back()) + ", the model is " + mm(h) +
                         " tall: the plan does not cover it (another model, size or placement?)");
  out.plan.boundaries = {0};
  for (std::size_t i = 0; i < tops.size(); ++i) {
    if (tops[i] > h + slack + 1e-9)
      throw InputError(name, where(i),
                       "layer top " + mm(tops[i]) + " is above the model's top " + mm(h) +
                           " by more than one layer (another model, size or placement?)");
    const bool last = i + 1 == tops.size();
    const int k = last ? profile.cells() : static_cast<int>(std::lround(tops[i] / grid));
    if (!last && k >= profile.cells()) {
      // A top at or above H before the last: the rest is above the model.
      continue;
    }
    if (k <= out.plan.boundaries.back()) {
      throw InputError(name, where(i),
                       "layer top " + mm(tops[i]) + " lies in the same " + mm(grid) +
                           " grid cell as the one below: use a finer grid");
    }
    out.plan.boundaries.push_back(k);
  }
  for (int i = 0; i < out.plan.layer_count(); ++i) {
    const int w = out.plan.width(i);
    if (w < profile.min_cells() || w > profile.max_cells()) ++out.outside_limits;
  }
  return out;
}

}  // namespace salient::core
