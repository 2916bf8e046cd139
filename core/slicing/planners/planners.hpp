// The planners behind make_planner(), and the parameter searches they share (internal).
#pragma once

#include <functional>
#include <memory>

#include "core/slicing/planner.hpp"

namespace salient::core::planners {

std::unique_ptr<Planner> make_fine();
std::unique_ptr<Planner> make_coarse();
std::unique_ptr<Planner> make_uniform();
std::unique_ptr<Planner> make_cusp();
std::unique_ptr<Planner> make_stepwise();
std::unique_ptr<Planner> make_ha13();
std::unique_ptr<Planner> make_hms();
std::unique_ptr<Planner> make_adapslice();
std::unique_ptr<Planner> make_exact();
std::unique_ptr<Planner> make_random();
std::unique_ptr<Planner> make_ceo();

// `planner` behind PlanRequest::first_cells: the fixed first layer, then `planner` on the
// profile above it (ZProfile::window) with the ε left over or one layer fewer.
std::unique_ptr<Planner> with_first_layer(std::unique_ptr<Planner> planner);

// For planners indexed by layer count: plan(n) for n in [fewest, most]. With an ε target the
// smallest n whose plan has E ≤ ε; with a count target that count, clamped (and noted).
PlanResult search_count(const PlanRequest& request, const std::function<LayerPlan(int)>& plan);

// For planners with a continuous parameter p in [lo, hi] where larger p gives fewer layers:
// bisection for the requested count, or for the largest p whose plan keeps E ≤ ε.
PlanResult search_parameter(const PlanRequest& request, double lo, double hi,
                            const std::function<LayerPlan(double)>& plan);

// The layer count asked for, clamped to what the profile allows, with a note when clamped.
int clamp_count(const ZProfile& profile, int requested, std::string& note);

}  // namespace salient::core::planners
