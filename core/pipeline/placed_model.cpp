#include "core/pipeline/placed_model.hpp"

#include "core/common/input_error.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::core {

PlacedModel load_placed(const MeshOptions& options, const std::string& values_file) {
  PlacedModel out;
  const auto up = parse_up_axis(options.up);
  if (!up) throw InputError("--up", {}, "expected x, y or z, got '" + options.up + "'");
  out.up = *up;
  if (values_file.empty()) {
    out.loaded = load_mesh(options.model);
  } else {
    MeshFile file = read_mesh_file(options.model);
    file.mesh.quality = read_vertex_values(values_file, file.mesh.vertex_count());
    out.loaded = repair_loaded(std::move(file), std::filesystem::path(options.model).filename().string());
  }
  PlacementOptions placement;
  placement.up = *up;
  placement.target_height = options.height;
  placement.scale = options.scale;
  placement.bed_center_x = options.bed_center_x;
  placement.bed_center_y = options.bed_center_y;
  out.placement = place_mesh(out.loaded.mesh, placement);
  return out;
}

}  // namespace salient::core
