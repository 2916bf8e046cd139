// Rectilinear infill: parallel lines at a spacing and angle, clipped to a region, ordered so
// that each line starts near where the last one ended.
#pragma once

#include "core/geometry/polygon_ops.hpp"

namespace salient::core {

// Lines are placed on a grid fixed in the bed's frame (not the region's), so sparse infill of
// successive layers stacks line on line.
Polylines rectilinear_infill(const Polygons& region, double spacing, double angle_radians);

}  // namespace salient::core
