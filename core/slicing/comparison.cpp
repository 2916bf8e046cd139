// compare_planners, compare_with_plan: two targets per planner, timed.
#include "core/slicing/comparison.hpp"

#include <algorithm>
#include <chrono>

namespace salient::core {
namespace {

PlanRequest with_target(const PlanRequest& base, PlanTarget target) {
  PlanRequest r = base;
  r.target = target;
  return r;
}

// Each planner at `count` layers and at E ≤ `reference_error`.
void add_rows(const PlanRequest& base, int count, double reference_error,
              std::span<const std::string_view> planners, Comparison& out) {
  const Objective& obj = base.objective;
  auto request = [&](PlanTarget target) { return with_target(base, target); };
  for (std::string_view name : planners) {
    const auto planner = make_planner(name);
    if (!planner) continue;
    base.run.check();
    ComparisonRow row;
    row.planner = std::string(name);
    const auto t0 = std::chrono::steady_clock::now();
    const PlanResult at_count = planner->plan(request(PlanTarget::count(count)));
    const PlanResult at_rsmd = planner->plan(request(PlanTarget::within(reference_error)));
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row.layers_at_count = at_count.plan.layer_count();
    row.rsmd_at_count = obj.rsmd(at_count.plan);
    row.layers_at_rsmd = at_rsmd.plan.layer_count();
    row.rsmd_at_rsmd = obj.rsmd(at_rsmd.plan);
    row.note = at_count.note.empty() ? at_rsmd.note : at_count.note;
    out.rows.push_back(std::move(row));
  }
}

}  // namespace

Comparison compare_planners(const PlanRequest& base, double rho, std::span<const std::string_view> planners) {
  const Objective& obj = base.objective;
  Comparison out;
  out.rho = rho;
  out.epsilon = obj.epsilon(rho);
  out.fine_layers = finest_layer_count(obj.profile(), base.first_cells);
  out.coarse_layers = fewest_layer_count(obj.profile(), base.first_cells);
  auto request = [&](PlanTarget target) { return with_target(base, target); };
  const PlanResult reference = make_planner("exact")->plan(request(PlanTarget::within(out.epsilon)));
  out.reference_layers = reference.plan.layer_count();
  out.reference_rsmd = obj.rsmd(reference.plan);
  add_rows(base, out.reference_layers, obj.error(reference.plan), planners, out);
  out.adapslice_trace = make_planner("adapslice")->plan(request(PlanTarget::within(out.epsilon))).trace;
  return out;
}

Comparison compare_with_plan(const PlanRequest& base, const LayerPlan& given, const std::string& label,
                             std::span<const std::string_view> planners) {
  const Objective& obj = base.objective;
  Comparison out;
  out.fine_layers = finest_layer_count(obj.profile(), base.first_cells);
  out.coarse_layers = fewest_layer_count(obj.profile(), base.first_cells);
  out.reference_layers = given.layer_count();
  out.reference_rsmd = obj.rsmd(given);
  ComparisonRow own;
  own.planner = label;
  own.layers_at_count = own.layers_at_rsmd = given.layer_count();
  own.rsmd_at_count = own.rsmd_at_rsmd = out.reference_rsmd;
  out.rows.push_back(own);
  const int count = std::clamp(given.layer_count(), out.coarse_layers, out.fine_layers);
  add_rows(base, count, std::max(0.0, obj.error(given)), planners, out);
  if (count != given.layer_count())
    for (std::size_t i = 1; i < out.rows.size(); ++i)
      out.rows[i].note = "at " + std::to_string(count) + " layers, the nearest count min/max layer allow" +
                         (out.rows[i].note.empty() ? "" : "; " + out.rows[i].note);
  return out;
}

}  // namespace salient::core
