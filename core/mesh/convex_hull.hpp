// convex_hull: the convex hull of a point set as a closed triangle mesh. A model put down on a
// flat bed rests on one of its hull's facets, so automatic orientation (core/orient) offers them.
#pragma once

#include <span>

#include "core/mesh/mesh.hpp"

namespace salient::core {

// The hull's triangles, counter-clockwise seen from outside (outward normals), over its own
// vertices (a subset of `points`). Coplanar hull facets come back triangulated. Empty when the
// points span no volume (fewer than four, or all on one plane): such a hull has no facet to stand
// on. Non-finite points are ignored.
Mesh convex_hull(std::span<const Vec3> points);

}  // namespace salient::core
