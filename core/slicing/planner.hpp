// Planner: one interface over every way of choosing layer thicknesses, selectable by name.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"
#include "core/slicing/layer_plan.hpp"
#include "core/slicing/layer_time_model.hpp"
#include "core/slicing/objective.hpp"

namespace salient::core {

// What a plan must achieve: at most `epsilon` loss (E ≤ ε) with the fewest layers, or exactly
// `layers` layers with the least loss. Each planner searches its own parameter for it.
struct PlanTarget {
  std::optional<double> epsilon;
  std::optional<int> layers;

  static PlanTarget within(double eps) { return {eps, std::nullopt}; }
  static PlanTarget count(int n) { return {std::nullopt, n}; }
};

// What `exact` minimises under an ε target: the estimated printing time (ours, the default), or
// the number of layers (the paper's T = N). The other planners search their own parameter for
// the fewest layers either way; every plan is then judged by the same time.
enum class PlanGoal { time, layers };

// The name table: "time", "layers" (in this order), and back.
const std::vector<std::string_view>& plan_goal_names();
std::optional<PlanGoal> parse_plan_goal(std::string_view name);
std::string_view to_string(PlanGoal goal);

struct PlanRequest {
  const Objective& objective;            // the metric plans are judged by
  const Mesh* mesh = nullptr;            // the placed mesh (for `ha13`, which cuts sections)
  const Objective* geometric = nullptr;  // the same metric with saliency ≡ 1 (for `ceo`)
  PlanTarget target;
  std::uint64_t seed = 1;  // for `random`
  RunContext run;
  PlanGoal goal = PlanGoal::layers;
  const LayerTimeModel* time = nullptr;  // the same cells as `objective`; needed for PlanGoal::time
  // The first layer is this many cells thick, fixed (the printer's first-layer height); the
  // planner plans the layers above it. 0: free.
  int first_cells = 0;
};

// One step of an iterative planner (the paper's Fig. 10).
struct PlanStep {
  std::string step;
  int layers;
  double error;
};

struct PlanResult {
  LayerPlan plan;
  std::string note;             // e.g. why the requested count could not be reached
  std::vector<PlanStep> trace;  // adapslice's steps
};

class Planner {
 public:
  virtual ~Planner() = default;
  virtual std::string_view name() const = 0;
  virtual PlanResult plan(const PlanRequest& request) const = 0;
};

// Every planner, in the order `compare` lists them (the name table's order).
enum class PlannerKind { exact, adapslice, hms, uniform, cusp, stepwise, ha13, ceo, random, fine, coarse };

// The name table: each planner's name as the CLI, the daemon and `compare` use it, and back.
const std::vector<std::string_view>& planner_names();
std::optional<PlannerKind> parse_planner(std::string_view name);
std::string_view to_string(PlannerKind kind);

std::unique_ptr<Planner> make_planner(PlannerKind kind);
// nullptr for an unknown name.
std::unique_ptr<Planner> make_planner(std::string_view name);

}  // namespace salient::core
