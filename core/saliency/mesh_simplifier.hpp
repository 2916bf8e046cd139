// Quadric edge-collapse simplification (Garland & Heckbert 1997) and isotropic remeshing
// (Botsch & Kobbelt 2004), through CGAL.
#pragma once

#include <cstddef>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

// A copy of `mesh` reduced to about `target_vertices` vertices (unchanged if it has fewer).
// Non-manifold input is split into manifold pieces first. Colours and quality are dropped.
// Throws Cancelled within about a thousand collapses of `run`'s token being cancelled.
Mesh simplify_mesh(const Mesh& mesh, std::size_t target_vertices, const RunContext& run = {});

// The spectral saliency's working mesh M′: `simplify_mesh`, then isotropically remeshed (three
// rounds) at its own mean edge length, so that no sliver's 1/d² weight dominates the Laplacian
// and M′ follows the surface more than the way the input was tessellated. Meshes below
// `target_vertices` are remeshed too.
Mesh working_mesh(const Mesh& mesh, std::size_t target_vertices, const RunContext& run = {});

}  // namespace salient::core
