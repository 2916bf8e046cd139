// Hole filling: closes a consistently oriented mesh's holes (loops of edges used by one face) with
// caps triangulated in the hole's own plane, as admesh's fill_holes does for PrusaSlicer, so an
// open bottom or an eye socket slices as a closed outline instead of being left out.
#pragma once

#include <cstddef>

#include "core/mesh/mesh.hpp"

namespace salient::core {

struct HoleFilling {
  std::size_t holes_filled = 0;  // loops capped
  std::size_t faces_added = 0;
  std::size_t holes_left = 0;  // loops not capped: through a pinched vertex, too long, or folded in plan
};

// Caps every simple hole of at most `max_edges` edges whose outline, seen along its mean normal,
// does not cross itself (ear clipping there, so no vertex is added and per-vertex colours and
// qualities stay valid). The caps run opposite to the faces along the hole, so an oriented mesh
// stays oriented.
HoleFilling fill_holes(Mesh& mesh, std::size_t max_edges = 4096);

}  // namespace salient::core
