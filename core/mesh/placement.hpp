// Placement: turn a model so its up axis is +Z, scale it, stand it on z = 0, centre it on the bed.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "core/mesh/mesh.hpp"

namespace salient::core {

enum class UpAxis { x, y, z };

// "x", "y" or "z"; nullopt otherwise.
std::optional<UpAxis> parse_up_axis(std::string_view name);
std::string_view up_axis_name(UpAxis axis);
// "0.12,-0.99,0" → that direction (not normalised); nullopt unless three finite numbers, not all 0.
std::optional<Vec3> parse_up_direction(std::string_view text);
// The proper rotation (determinant +1) that turns unit vector `d` to +Z, applied to `p`.
Vec3 turn_to_z(const Vec3& p, const Vec3& d);

struct PlacementOptions {
  UpAxis up = UpAxis::z;
  // Any direction of the model to turn to +Z (automatic orientation); overrides `up` when set.
  // Need not be unit length; must be finite and non-zero.
  std::optional<Vec3> up_direction;
  std::optional<double> target_height;        // mm along the new Z; exclusive with scale != 1
  double scale = 1.0;                         // uniform factor, applied when no target height is set
  double bed_center_x = 0, bed_center_y = 0;  // mm, where the footprint's centre goes
};

struct Placement {
  double scale = 1;
  Vec3 translation{};    // added after rotation and scaling
  BoundingBox bounds{};  // of the placed mesh
};

// Places `mesh` in place. Throws InputError (source "placement") for impossible options: a
// non-positive or non-finite height or scale, both at once, or a flat model scaled to a height.
Placement place_mesh(Mesh& mesh, const PlacementOptions& options);

}  // namespace salient::core
