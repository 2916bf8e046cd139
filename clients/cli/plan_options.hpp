// Options shared by `plan` and `compare`, and the pipeline they run: load, place, saliency,
// z-profile, objective.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "clients/cli/mesh_options.hpp"
#include "core/slicing/objective.hpp"
#include "core/slicing/planner.hpp"

namespace CLI {
class App;
}

namespace salient::cli {

struct PlanOptions {
  MeshOptions mesh;
  double min_layer = 0.1, max_layer = 0.4, grid = 0.01;
  std::optional<double> rho;
  std::optional<int> layers;
  std::optional<double> layer_height;
  std::string metric = "area";
  std::string planner = "exact";
  std::string saliency = "uniform";
  std::string saliency_file;
  std::uint64_t seed = 1;
  bool json = false;
};

void add_plan_options(CLI::App& command, PlanOptions& options);

// Everything a planner needs, built once. Members refer to each other: not copyable.
struct PlanningSetup {
  PlacedModel model;
  std::vector<float> saliency;
  std::unique_ptr<core::ZProfile> profile;
  std::unique_ptr<core::Objective> objective, geometric;
  double rho = 0.05;
  std::uint64_t seed = 1;

  core::PlanRequest request(core::PlanTarget target) const;
};

// Throws core::InputError naming the option or file at fault.
std::unique_ptr<PlanningSetup> prepare(const PlanOptions& options);

// The target the options ask for (ρ by default; a count from --layers or --layer-height).
core::PlanTarget target_of(const PlanOptions& options, const PlanningSetup& setup);

}  // namespace salient::cli
