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

struct PlacementOptions {
  UpAxis up = UpAxis::z;
  std::optional<double> target_height;  // mm along the new Z; exclusive with scale != 1
  double scale = 1.0;                   // uniform factor, applied when no target height is set
  double bed_center_x = 0, bed_center_y = 0;  // mm, where the footprint's centre goes
};

struct Placement {
  double scale = 1;
  Vec3 translation{};  // added after rotation and scaling
  BoundingBox bounds{};  // of the placed mesh
};

// Places `mesh` in place. Throws InputError (source "placement") for impossible options: a
// non-positive or non-finite height or scale, both at once, or a flat model scaled to a height.
Placement place_mesh(Mesh& mesh, const PlacementOptions& options);

}  // namespace salient::core
