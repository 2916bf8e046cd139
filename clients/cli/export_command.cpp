// `salient export-3mf MODEL PLAN.json -o model.3mf`: the model and our plan as a 3MF that
// PrusaSlicer opens with the plan as its variable layer height.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "core/export/plan_json.hpp"
#include "core/export/three_mf.hpp"

namespace salient::cli {
namespace {

struct ExportOptions {
  core::MeshOptions mesh;
  std::string plan, output;
};

// Layer boundaries from a plan file (any salient-plan: `salient plan -o`, `plan --segment -o`, the
// daemon's /plan); errors name the file and field.
std::vector<double> read_plan_boundaries(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError(name, {}, "cannot open for reading");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return core::read_plan_json(text, name).boundaries();
}

}  // namespace

void add_export_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand("export-3mf", "Write the model and a plan as a 3MF for PrusaSlicer");
  add_mesh_options(*cmd, o->mesh, true);
  cmd->add_option("PLAN", o->plan,
                  "Plan JSON from `salient plan -o` (also --segment) or salientd's /plan (same "
                  "--up/--height/--scale as then)")
      ->required();
  cmd->add_option("-o,--output", o->output, "3MF file to write")->required();
  cmd->callback([o, &action] {
    action = [o] {
      resolve_auto_up(o->mesh, nullptr, false);
      const std::vector<double> z = read_plan_boundaries(o->plan);
      const core::PlacedModel m = core::load_placed(o->mesh);
      const double height = m.placement.bounds.size().z;
      if (std::fabs(z.back() - height) > 1e-3)
        throw core::InputError(std::filesystem::path(o->plan).filename().string(), {},
                               "was made for a model " + std::to_string(z.back()) +
                                   " mm tall, this one is placed at " + std::to_string(height) +
                                   " mm: give the same --up, --height or --scale as for the plan");
      const std::string name = std::filesystem::path(o->mesh.model).stem().string();
      core::write_three_mf(o->output, m.loaded.mesh, z, name);
      std::printf("%s: %zu layers -> %s\n", name.c_str(), z.size() - 1, o->output.c_str());
      return 0;
    };
  });
}

}  // namespace salient::cli
