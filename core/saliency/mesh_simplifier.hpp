// Quadric edge-collapse simplification (Garland & Heckbert 1997, through CGAL).
#pragma once

#include <cstddef>

#include "core/mesh/mesh.hpp"

namespace salient::core {

// A copy of `mesh` reduced to about `target_vertices` vertices (unchanged if it has fewer).
// Non-manifold input is split into manifold pieces first. Colours and quality are dropped.
Mesh simplify_mesh(const Mesh& mesh, std::size_t target_vertices);

}  // namespace salient::core
