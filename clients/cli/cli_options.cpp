#include "clients/cli/cli_options.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "core/pipeline/auto_orient.hpp"
#include "core/printer/printer_profile.hpp"

namespace salient::cli {

void add_mesh_options(CLI::App& command, core::MeshOptions& options, bool allow_auto) {
  command.add_option("MODEL", options.model, "Model file (STL, OBJ, PLY or OFF)")->required();
  command
      .add_option(
          "--up", options.up,
          allow_auto
              ? "Up: x, y, z, a direction DX,DY,DZ, or auto (the best of three orientations, paper §6; "
                "with --height, the tallest of them gets that height)"
              : "Up: x, y, z, or a direction DX,DY,DZ")
      ->check(CLI::Validator(
          [allow_auto](std::string& v) -> std::string {
            if (core::parse_up_axis(v) || core::parse_up_direction(v) || (allow_auto && v == "auto"))
              return {};
            return std::string("expected x, y, z") + (allow_auto ? ", auto" : "") +
                   " or a direction like 0,-1,0.2, got '" + v + "'";
          },
          "UP"))
      ->capture_default_str();
  command.add_option("--height", options.height, "Scale the model to this height (mm)");
  command.add_option("--scale", options.scale, "Scale the model by this factor")->capture_default_str();
}

void add_plan_options(CLI::App& cmd, core::PlanOptions& o, bool& json) {
  add_mesh_options(cmd, o.mesh, true);
  cmd.add_option("--min-layer", o.min_layer, "Thinnest printable layer α (mm)")->capture_default_str();
  cmd.add_option("--max-layer", o.max_layer, "Thickest printable layer ᾱ (mm)")->capture_default_str();
  cmd.add_option("--grid", o.grid, "Grid δ that layer boundaries snap to (mm)")->capture_default_str();
  auto* rho = cmd.add_option("--rho", o.rho, "Allowed loss ε = ρ·E(coarse), 0..1 (default 0.05)");
  auto* layers = cmd.add_option("--layers", o.layers, "Plan exactly this many layers");
  auto* height =
      cmd.add_option("--layer-height", o.layer_height, "Uniform thickness (mm), for --planner uniform");
  rho->excludes(layers)->excludes(height);
  layers->excludes(height);
  cmd.add_option("--metric", o.metric, "Quality metric: area (ours) or paper (eq. 1)")
      ->check(CLI::IsMember({"area", "paper"}))
      ->capture_default_str();
  cmd.add_option("--saliency", o.saliency,
                 "Saliency: spectral (the paper's), lee05, painted (vertex quality/colour) or uniform")
      ->check(CLI::IsMember({"spectral", "lee05", "painted", "uniform"}))
      ->capture_default_str();
  cmd.add_option(
      "--saliency-file", o.saliency_file,
      "Per-vertex saliency, one value per line in the model file's vertex order (implies painted)");
  cmd.add_option("--seed", o.seed, "Seed for the random planner")->capture_default_str();
  cmd.add_flag(
      "--segment", o.segment,
      "SegOpt (paper §5): cut the model by a vertical plane where slicing its parts apart saves time");
  cmd.add_option("--segment-depth", o.segment_depth,
                 "With --segment: levels of cutting (2 and more cut each part again)")
      ->capture_default_str()
      ->check(CLI::Range(1, 4));
  cmd.add_option(
         "--segment-planes", o.segment_planes,
         "With --segment: how many of the best planes (by seam cost) to plan and time; the fastest is kept")
      ->capture_default_str()
      ->check(CLI::Range(1, 20));
  cmd.add_flag("--json", json, "Print JSON instead of text");
}

}  // namespace salient::cli

namespace salient::cli {

void resolve_auto_up(core::MeshOptions& mesh, const core::PlanOptions* plan, bool quiet) {
  if (mesh.up != "auto") return;
  core::SliceSettings settings;
  if (plan) settings.plan = *plan;
  settings.plan.mesh = mesh;
  const auto printer = core::builtin_printer("generic-i3");
  const core::OrientationReport report = core::choose_orientation(settings, *printer, {});
  if (!quiet) print_orientation(report);
  mesh.up = report.up;
  if (report.scale) mesh.height.reset(), mesh.scale = *report.scale;
}

void print_orientation(const core::OrientationReport& report) {
  std::printf("orientation (--up auto): OS = 0.3 TimeS + 0.3 VolS + 0.3 StaS over %zu candidates\n",
              report.candidates.size());
  for (std::size_t i = 0; i < report.candidates.size(); ++i) {
    const core::OrientationScore& c = report.candidates[i];
    std::printf("  up %6.3f,%6.3f,%6.3f  %7.1f min %5d layers  TimeS %.3f  VolS %.4f  StaS %.4f  OS %.4f%s\n",
                c.up.x, c.up.y, c.up.z, c.minutes, c.layers, c.time_score, c.volume_score, c.stability_score,
                c.score, i == report.best ? "  <- chosen" : "");
  }
}

}  // namespace salient::cli
