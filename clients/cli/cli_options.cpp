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

SettingOptions add_plan_options(CLI::App& cmd, core::Settings& settings, bool& json, unsigned command) {
  cmd.add_option("MODEL", settings.slice.plan.mesh.model, "Model file (STL, OBJ, PLY or OFF)")->required();
  SettingOptions options(cmd, command);
  cmd.add_flag("--json", json, "Print JSON instead of text");
  return options;
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
