#include "core/pipeline/placed_model.hpp"

#include "core/common/input_error.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::core {

namespace {

struct Up {
  std::optional<UpAxis> axis;
  std::optional<Vec3> direction;
};

Up parsed_up(const std::string& text) {
  Up up{parse_up_axis(text), std::nullopt};
  if (!up.axis) up.direction = parse_up_direction(text);
  if (!up.axis && !up.direction) {
    std::string message = text == "auto"
                              ? "'auto' is only for slice, plan and jobs (it slices three orientations)"
                              : "expected x, y, z, auto or a direction like 0,-1,0.2, got '";
    if (text != "auto") message.append(text).append("'");
    throw InputError(SettingId::up, message);
  }
  return up;
}

Placement place(Mesh& mesh, const MeshOptions& options, const Up& up) {
  PlacementOptions placement;
  if (up.axis) placement.up = *up.axis;
  placement.up_direction = up.direction;
  placement.target_height = options.height;
  placement.scale = options.scale;
  placement.bed_center_x = options.bed_center_x;
  placement.bed_center_y = options.bed_center_y;
  return place_mesh(mesh, placement);
}

}  // namespace

Placement place_by_options(Mesh& mesh, const MeshOptions& options) {
  return place(mesh, options, parsed_up(options.up));
}

PlacedModel load_placed(const MeshOptions& options, const std::string& values_file) {
  PlacedModel out;
  const Up up = parsed_up(options.up);  // before loading: a bad option should not wait for a big model
  if (up.axis) out.up = *up.axis;
  out.up_direction = up.direction;
  if (values_file.empty()) {
    out.loaded = load_mesh(options.model);
  } else {
    MeshFile file = read_mesh_file(options.model);
    file.mesh.quality = read_vertex_values(values_file, file.mesh.vertex_count());
    out.loaded = repair_loaded(std::move(file), std::filesystem::path(options.model).filename().string());
  }
  out.placement = place(out.loaded.mesh, options, up);
  return out;
}

}  // namespace salient::core
