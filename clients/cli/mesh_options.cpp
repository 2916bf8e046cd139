// Shared model options: load, repair and place in one call.
#include "clients/cli/mesh_options.hpp"

#include <CLI/CLI.hpp>

#include "core/common/input_error.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::cli {

void add_mesh_options(CLI::App& command, MeshOptions& options) {
  command.add_option("MODEL", options.model, "Model file (STL, OBJ, PLY or OFF)")->required();
  command.add_option("--up", options.up, "Axis of the model that points up: x, y or z")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  command.add_option("--height", options.height, "Scale the model to this height (mm)");
  command.add_option("--scale", options.scale, "Scale the model by this factor")->capture_default_str();
}

PlacedModel load_placed(const MeshOptions& options, const std::string& values_file) {
  PlacedModel out;
  const auto up = core::parse_up_axis(options.up);
  if (!up) throw core::InputError("--up", {}, "expected x, y or z, got '" + options.up + "'");
  out.up = *up;
  if (values_file.empty()) {
    out.loaded = core::load_mesh(options.model);
  } else {
    core::MeshFile file = core::read_mesh_file(options.model);
    file.mesh.quality = core::read_vertex_values(values_file, file.mesh.vertex_count());
    out.loaded = core::repair_loaded(std::move(file), std::filesystem::path(options.model).filename().string());
  }
  core::PlacementOptions placement;
  placement.up = *up;
  placement.target_height = options.height;
  placement.scale = options.scale;
  placement.bed_center_x = options.bed_center_x;
  placement.bed_center_y = options.bed_center_y;
  out.placement = core::place_mesh(out.loaded.mesh, placement);
  return out;
}

}  // namespace salient::cli
