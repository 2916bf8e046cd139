// `salient export-3mf MODEL PLAN.json -o model.3mf`: the model and our plan as a 3MF that
// PrusaSlicer opens with the plan as its variable layer height.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "core/export/three_mf.hpp"

namespace salient::cli {
namespace {

struct ExportOptions {
  core::MeshOptions mesh;
  std::string plan, output;
};

// Layer boundaries from a plan written by `salient plan -o`; errors name the file and field.
std::vector<double> read_plan_boundaries(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  std::ifstream in(path);
  if (!in) throw core::InputError(name, {}, "cannot open for reading");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw core::InputError(name, core::InputLocation::at_byte(e.byte), "not valid JSON");
  }
  if (!j.contains("layers") || !j["layers"].is_array() || j["layers"].empty())
    throw core::InputError(name, {},
                           "field 'layers' is missing or empty (write plans with `salient plan -o`)");
  std::vector<double> z{0};
  for (std::size_t i = 0; i < j["layers"].size(); ++i) {
    const auto& l = j["layers"][i];
    if (!l.contains("z_top") || !l["z_top"].is_number())
      throw core::InputError(name, {},
                             "field 'layers[" + std::to_string(i) + "].z_top' is missing or not a number");
    const double top = l["z_top"].get<double>();
    if (!(top > z.back()))
      throw core::InputError(name, {}, "field 'layers[" + std::to_string(i) + "].z_top' does not rise");
    z.push_back(top);
  }
  return z;
}

}  // namespace

void add_export_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand("export-3mf", "Write the model and a plan as a 3MF for PrusaSlicer");
  add_mesh_options(*cmd, o->mesh, true);
  cmd->add_option("PLAN", o->plan, "Plan JSON from `salient plan -o` (same --up/--height/--scale as then)")
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
