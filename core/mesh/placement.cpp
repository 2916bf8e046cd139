// Placement. The rotations are proper (determinant +1), so orientation and volume sign survive:
// y-up maps (x, y, z) to (x, -z, y), which is how Y-up exchange formats are stood up; x-up is
// the cyclic permutation (x, y, z) to (y, z, x).
#include "core/mesh/placement.hpp"

#include <cmath>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

[[noreturn]] void bad_option(const std::string& message) {
  throw InputError("placement", {}, message);
}

Vec3 rotate_up(const Vec3& p, UpAxis up) {
  switch (up) {
    case UpAxis::x: return {p.y, p.z, p.x};
    case UpAxis::y: return {p.x, -p.z, p.y};
    case UpAxis::z: return p;
  }
  return p;
}

}  // namespace

std::optional<UpAxis> parse_up_axis(std::string_view name) {
  if (name == "x") return UpAxis::x;
  if (name == "y") return UpAxis::y;
  if (name == "z") return UpAxis::z;
  return std::nullopt;
}

std::string_view up_axis_name(UpAxis axis) {
  switch (axis) {
    case UpAxis::x: return "x";
    case UpAxis::y: return "y";
    case UpAxis::z: return "z";
  }
  return "z";
}

Placement place_mesh(Mesh& mesh, const PlacementOptions& options) {
  if (options.target_height && !(std::isfinite(*options.target_height) && *options.target_height > 0))
    bad_option("--height must be a positive number of millimetres");
  if (!(std::isfinite(options.scale) && options.scale > 0)) bad_option("--scale must be a positive number");
  if (options.target_height && options.scale != 1.0) bad_option("give either --height or --scale, not both");

  for (Vec3& p : mesh.positions) p = rotate_up(p, options.up);
  const BoundingBox turned = bounding_box(mesh);
  Placement result;
  result.scale = options.scale;
  if (options.target_height) {
    const double height = turned.size().z;
    if (!(height > 0)) bad_option("the model is flat along its up axis; it cannot be scaled to a height");
    result.scale = *options.target_height / height;
  }
  const Vec3 c = turned.center();
  result.translation = Vec3{options.bed_center_x, options.bed_center_y, 0} -
                       Vec3{c.x * result.scale, c.y * result.scale, turned.min.z * result.scale};
  for (Vec3& p : mesh.positions) p = p * result.scale + result.translation;
  result.bounds = bounding_box(mesh);
  // Snap the lowest point to exactly 0 (rounding can leave it at -1e-15).
  for (Vec3& p : mesh.positions)
    if (p.z < 0) p.z = 0;
  result.bounds.min.z = 0;
  return result;
}

}  // namespace salient::core
