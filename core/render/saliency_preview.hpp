// A preview of per-vertex values on a mesh: three orthographic views (front, side, top) side by
// side, heat-coloured and shaded, by a small z-buffer rasteriser (no GL needed).
#pragma once

#include <span>

#include "core/mesh/mesh.hpp"
#include "core/render/image.hpp"

namespace salient::core {

// Blue (0) through cyan, green and yellow to red (1).
Color heat_color(float value);

Image render_preview(const Mesh& mesh, std::span<const float> values, int view_size = 360);

}  // namespace salient::core
