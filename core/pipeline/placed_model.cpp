#include "core/pipeline/placed_model.hpp"

#include "core/common/input_error.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::core {

PlacedModel load_placed(const MeshOptions& options, const std::string& values_file) {
  PlacedModel out;
  const auto up = parse_up_axis(options.up);
  if (!up) out.up_direction = parse_up_direction(options.up);
  if (!up && !out.up_direction) {
    std::string message = options.up == "auto"
                              ? "'auto' is only for slice, plan and jobs (it slices three orientations)"
                              : "expected x, y, z, auto or a direction like 0,-1,0.2, got '";
    if (options.up != "auto") message.append(options.up).append("'");
    throw InputError(SettingId::up, message);
  }
  if (up) out.up = *up;
  if (values_file.empty()) {
    out.loaded = load_mesh(options.model);
  } else {
    MeshFile file = read_mesh_file(options.model);
    file.mesh.quality = read_vertex_values(values_file, file.mesh.vertex_count());
    out.loaded = repair_loaded(std::move(file), std::filesystem::path(options.model).filename().string());
  }
  PlacementOptions placement;
  if (up) placement.up = *up;
  placement.up_direction = out.up_direction;
  placement.target_height = options.height;
  placement.scale = options.scale;
  placement.bed_center_x = options.bed_center_x;
  placement.bed_center_y = options.bed_center_y;
  out.placement = place_mesh(out.loaded.mesh, placement);
  return out;
}

}  // namespace salient::core
