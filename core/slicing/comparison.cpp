// compare_planners: two targets per planner, timed.
#include "core/slicing/comparison.hpp"

#include <chrono>

namespace salient::core {

Comparison compare_planners(const PlanRequest& base, double rho, std::span<const std::string_view> planners) {
  const Objective& obj = base.objective;
  Comparison out;
  out.rho = rho;
  out.epsilon = obj.epsilon(rho);
  out.fine_layers = obj.profile().most_layers();
  out.coarse_layers = obj.profile().fewest_layers();
  auto request = [&](PlanTarget target) {
    PlanRequest r = base;
    r.target = target;
    return r;
  };
  const PlanResult reference = make_planner("exact")->plan(request(PlanTarget::within(out.epsilon)));
  out.reference_layers = reference.plan.layer_count();
  out.reference_rsmd = obj.rsmd(reference.plan);
  const double reference_error = obj.error(reference.plan);
  for (std::string_view name : planners) {
    const auto planner = make_planner(name);
    if (!planner) continue;
    base.run.check();
    ComparisonRow row;
    row.planner = std::string(name);
    const auto t0 = std::chrono::steady_clock::now();
    const PlanResult at_count = planner->plan(request(PlanTarget::count(out.reference_layers)));
    const PlanResult at_rsmd = planner->plan(request(PlanTarget::within(reference_error)));
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row.layers_at_count = at_count.plan.layer_count();
    row.rsmd_at_count = obj.rsmd(at_count.plan);
    row.layers_at_rsmd = at_rsmd.plan.layer_count();
    row.rsmd_at_rsmd = obj.rsmd(at_rsmd.plan);
    row.note = at_count.note.empty() ? at_rsmd.note : at_count.note;
    out.rows.push_back(std::move(row));
  }
  out.adapslice_trace = make_planner("adapslice")->plan(request(PlanTarget::within(out.epsilon))).trace;
  return out;
}

}  // namespace salient::core
