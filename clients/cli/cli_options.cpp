#include "clients/cli/cli_options.hpp"

#include <CLI/CLI.hpp>

namespace salient::cli {

void add_mesh_options(CLI::App& command, core::MeshOptions& options) {
  command.add_option("MODEL", options.model, "Model file (STL, OBJ, PLY or OFF)")->required();
  command.add_option("--up", options.up, "Axis of the model that points up: x, y or z")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  command.add_option("--height", options.height, "Scale the model to this height (mm)");
  command.add_option("--scale", options.scale, "Scale the model by this factor")->capture_default_str();
}

void add_plan_options(CLI::App& cmd, core::PlanOptions& o, bool& json) {
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
  cmd.add_flag("--json", json, "Print JSON instead of text");
}

}  // namespace salient::cli
