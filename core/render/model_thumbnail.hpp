// A thumbnail of a model as printers' screens and OctoPrint show it: one shaded orthographic view,
// three-quarter from the front-right and above, fitted into any width × height (no GL needed).
#pragma once

#include "core/mesh/mesh.hpp"
#include "core/render/image.hpp"

namespace salient::core {

// The model in PrusaSlicer's orange, lit from the viewer's upper left, on a white background;
// `width` and `height` in pixels (≥ 1). An empty mesh gives a blank image.
Image render_thumbnail(const Mesh& mesh, int width, int height);

}  // namespace salient::core
