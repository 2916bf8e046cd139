// Planning options and pipeline.
#include "clients/cli/plan_options.hpp"

#include <CLI/CLI.hpp>
#include <cmath>

#include "core/common/input_error.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::cli {

void add_plan_options(CLI::App& cmd, PlanOptions& o) {
  add_mesh_options(cmd, o.mesh);
  cmd.add_option("--min-layer", o.min_layer, "Thinnest printable layer α (mm)")->capture_default_str();
  cmd.add_option("--max-layer", o.max_layer, "Thickest printable layer ᾱ (mm)")->capture_default_str();
  cmd.add_option("--grid", o.grid, "Grid δ that layer boundaries snap to (mm)")->capture_default_str();
  auto* rho = cmd.add_option("--rho", o.rho, "Allowed loss ε = ρ·E(coarse), 0..1 (default 0.05)");
  auto* layers = cmd.add_option("--layers", o.layers, "Plan exactly this many layers");
  auto* height = cmd.add_option("--layer-height", o.layer_height, "Uniform thickness (mm), for --planner uniform");
  rho->excludes(layers)->excludes(height);
  layers->excludes(height);
  cmd.add_option("--metric", o.metric, "Quality metric: area (ours) or paper (eq. 1)")
      ->check(CLI::IsMember({"area", "paper"}))
      ->capture_default_str();
  cmd.add_option("--saliency", o.saliency,
                 "Saliency: spectral (the paper's), lee05, painted (vertex quality/colour) or uniform")
      ->check(CLI::IsMember({"spectral", "lee05", "painted", "uniform"}))
      ->capture_default_str();
  cmd.add_option("--saliency-file", o.saliency_file,
                 "Per-vertex saliency, one value per line in the model file's vertex order (implies painted)");
  cmd.add_option("--seed", o.seed, "Seed for the random planner")->capture_default_str();
  cmd.add_flag("--json", o.json, "Print JSON instead of text");
}

core::PlanRequest PlanningSetup::request(core::PlanTarget target) const {
  return core::PlanRequest{*objective, &model.loaded.mesh, geometric.get(), target, seed, {}};
}

std::unique_ptr<PlanningSetup> prepare(const PlanOptions& o) {
  if (o.rho) core::validate_rho(*o.rho);
  if (o.layers && *o.layers <= 0) throw core::InputError("--layers", {}, "must be a positive number of layers");
  if (o.layer_height && !(*o.layer_height > 0)) throw core::InputError("--layer-height", {}, "must be positive");
  if (o.layer_height && o.planner != "uniform")
    throw core::InputError("--layer-height", {}, "applies to --planner uniform; use --layers for " + o.planner);
  core::SlicingParams params{o.min_layer, o.max_layer, o.grid};
  core::validate(params);  // before loading: a bad option should not wait for a big model
  const auto metric = core::parse_metric(o.metric);
  if (!metric) throw core::InputError("--metric", {}, "expected area or paper, got '" + o.metric + "'");
  auto method = core::parse_saliency_method(o.saliency);
  if (!method) throw core::InputError("--saliency", {}, "expected spectral, lee05, painted or uniform, got '" + o.saliency + "'");
  if (!o.saliency_file.empty()) method = core::SaliencyMethod::painted;

  auto s = std::make_unique<PlanningSetup>();
  s->model = load_placed(o.mesh, o.saliency_file);
  const std::string name = std::filesystem::path(o.mesh.model).filename().string();
  s->saliency = core::compute_saliency(s->model.loaded.mesh, *method, name);
  s->profile = std::make_unique<core::ZProfile>(core::ZProfile::build(s->model.loaded.mesh, s->saliency, params));
  s->objective = std::make_unique<core::Objective>(*s->profile, *metric, false);
  s->geometric = std::make_unique<core::Objective>(*s->profile, *metric, true);
  s->rho = o.rho.value_or(0.05);
  s->seed = o.seed;
  return s;
}

core::PlanTarget target_of(const PlanOptions& o, const PlanningSetup& s) {
  if (o.layers) return core::PlanTarget::count(*o.layers);
  if (o.layer_height)
    return core::PlanTarget::count(std::max(1, static_cast<int>(std::lround(s.profile->height() / *o.layer_height))));
  return core::PlanTarget::within(s.objective->epsilon(s.rho));
}

}  // namespace salient::cli
