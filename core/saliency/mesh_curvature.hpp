// Per-vertex mean curvature from the cotangent Laplace–Beltrami operator.
#pragma once

#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::core {

// H_i = −½ (Δx)_i · n_i with Δ the cotangent Laplacian over barycentric vertex areas and n_i
// the area-weighted vertex normal: positive where the surface is convex. Units 1/length.
std::vector<double> mean_curvature(const Mesh& mesh);

// Area-weighted unit vertex normals.
std::vector<Vec3> vertex_normals(const Mesh& mesh);

}  // namespace salient::core
