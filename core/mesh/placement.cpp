// Placement. The rotations are proper (determinant +1), so orientation and volume sign survive:
// y-up maps (x, y, z) to (x, -z, y), which is how Y-up exchange formats are stood up; x-up is
// the cyclic permutation (x, y, z) to (y, z, x).
#include "core/mesh/placement.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

[[noreturn]] void bad_option(const std::string& message) {
  throw InputError("placement", {}, message);
}

Vec3 rotate_up(const Vec3& p, UpAxis up) {
  switch (up) {
    case UpAxis::x:
      return {p.y, p.z, p.x};
    case UpAxis::y:
      return {p.x, -p.z, p.y};
    case UpAxis::z:
      return p;
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
    case UpAxis::x:
      return "x";
    case UpAxis::y:
      return "y";
    case UpAxis::z:
      return "z";
  }
  return "z";
}

std::optional<Vec3> parse_up_direction(std::string_view text) {
  double v[3];
  std::size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t comma = i < 2 ? text.find(',', start) : text.size();
    if (comma == std::string_view::npos) return std::nullopt;
    const std::string part(text.substr(start, comma - start));
    char* end = nullptr;
    v[i] = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(v[i])) return std::nullopt;
    start = comma + 1;
  }
  const Vec3 d{v[0], v[1], v[2]};
  if (!(norm(d) > 1e-12)) return std::nullopt;
  return d;
}

Vec3 turn_to_z(const Vec3& p, const Vec3& d) {
  // Rodrigues about k = d × z; for d = -z, half a turn about x.
  const Vec3 z{0, 0, 1};
  const double c = std::clamp(dot(d, z), -1.0, 1.0);
  const Vec3 axis = cross(d, z);
  const double s = norm(axis);
  if (s < 1e-12) return c > 0 ? p : Vec3{p.x, -p.y, -p.z};
  const Vec3 k = axis / s;
  return p * c + cross(k, p) * s + k * (dot(k, p) * (1 - c));
}

Placement place_mesh(Mesh& mesh, const PlacementOptions& options) {
  if (options.target_height && !(std::isfinite(*options.target_height) && *options.target_height > 0))
    bad_option("{height} must be a positive number of millimetres");
  if (!(std::isfinite(options.scale) && options.scale > 0)) bad_option("{scale} must be a positive number");
  if (options.target_height && options.scale != 1.0) bad_option("give either {height} or {scale}, not both");

  if (options.up_direction) {
    const Vec3 d = *options.up_direction;
    if (!(is_finite(d) && norm(d) > 1e-12)) bad_option("{up}: the direction must be finite and not zero");
    const Vec3 unit = d / norm(d);
    for (Vec3& p : mesh.positions) p = turn_to_z(p, unit);
  } else {
    for (Vec3& p : mesh.positions) p = rotate_up(p, options.up);
  }
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
