// Planning options and what a planner needs, built in one call: load, place, saliency, z-profile,
// objective. Shared by the CLI's plan, compare and slice and by the daemon's jobs.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.hpp"
#include "core/pipeline/placed_model.hpp"
#include "core/pipeline/work_bounds.hpp"
#include "core/saliency/saliency.hpp"
#include "core/saliency/saliency_cache.hpp"
#include "core/slicing/objective.hpp"
#include "core/slicing/planner.hpp"

namespace salient::core {

struct PlanOptions {
  MeshOptions mesh;
  double min_layer = 0.1, max_layer = 0.4, grid = 0.01;
  std::optional<double> rho;
  std::optional<int> layers;
  std::optional<double> layer_height;
  Metric metric = Metric::area;
  PlanGoal objective = PlanGoal::time;  // what `exact` minimises within ε
  PlannerKind planner = PlannerKind::exact;
  SaliencyMethod saliency = SaliencyMethod::spectral;
  std::string saliency_file;  // per-vertex values (implies painted)
  std::uint64_t seed = 1;
  bool segment = false;    // SegOpt (paper §5): cut by a vertical plane where that saves time
  int segment_depth = 1;   // levels of cutting (2+: each part is cut again where that saves time)
  int segment_planes = 1;  // planes timed, best seam cost first (the paper times only the best)
  // The printer's values (slice_model sets them from its profile; `plan` uses generic-i3's):
  // the fixed first layer (mm, rounded to the grid and kept within α..ᾱ; 0: free), the height a
  // user would print at otherwise (the results' second baseline), and what a layer's time is.
  double first_layer = 0.2, default_layer = 0.2;
  TimeModelParams time_model;
  SaliencyCache* saliency_cache = nullptr;  // not a setting: where a caller keeps saliency for reuse
  std::optional<BuildVolume> build_volume;  // not a setting: the printer's, where there is one
};

// Everything a planner needs, built once. Members refer to each other: not copyable.
struct PlanningSetup {
  PlacedModel model;
  std::vector<float> saliency;
  std::unique_ptr<ZProfile> profile;
  std::unique_ptr<Objective> objective, geometric;
  std::unique_ptr<LayerTimeModel> time;
  PlanGoal goal = PlanGoal::time;
  int first_cells = 0;         // the fixed first layer, in cells (0: free)
  double default_layer = 0.2;  // mm
  double rho = 0.05;
  std::uint64_t seed = 1;
  std::string saliency_text;  // what made `saliency`, as saliency_text(options) names it

  PlanRequest request(PlanTarget target) const;
};

// The checks that need no model (layer limits, ρ, the target, --segment's conditions), in the
// order prepare() makes them. Throws InputError naming the setting at fault.
void check_plan_options(const PlanOptions& options);

// Throws InputError naming the setting or file at fault (check_plan_options first).
// Reports the phases load, saliency and profile through `run`, and stops when it is cancelled.
std::unique_ptr<PlanningSetup> prepare(const PlanOptions& options, const RunContext& run = {});

// The saliency the options give: a saliency file's is painted, whatever `saliency` says.
SaliencyMethod saliency_method(const PlanOptions& options);
// The same as reports name it: "spectral saliency", or "painted saliency from FILE" (its name).
std::string saliency_text(const PlanOptions& options);

// The target the options ask for (ρ by default; a count from --layers or --layer-height).
PlanTarget target_of(const PlanOptions& options, const PlanningSetup& setup);

}  // namespace salient::core
