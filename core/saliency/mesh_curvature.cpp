// Mean curvature (Meyer et al. 2003, with barycentric instead of mixed Voronoi areas: robust on
// obtuse scanned triangles). Cotangents are clamped so a sliver cannot dominate its neighbours.
#include "core/saliency/mesh_curvature.hpp"

#include <algorithm>

namespace salient::core {

std::vector<Vec3> vertex_normals(const Mesh& mesh) {
  std::vector<Vec3> n(mesh.vertex_count());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3 an = area_normal(mesh, t);
    for (std::uint32_t v : mesh.triangles[t]) n[v] += an;
  }
  for (Vec3& v : n) {
    const double len = norm(v);
    if (len > 0) v = v / len;
  }
  return n;
}

std::vector<double> mean_curvature(const Mesh& mesh) {
  const std::size_t nv = mesh.vertex_count();
  std::vector<Vec3> laplace(nv);
  std::vector<double> area(nv, 0);
  constexpr double max_cot = 1e3;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    const double a = 0.5 * norm(area_normal(mesh, t));
    if (!(a > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      // The angle at corner k weighs the opposite edge (k+1, k+2).
      const std::uint32_t i = tri[k], j = tri[(k + 1) % 3], l = tri[(k + 2) % 3];
      const Vec3 u = mesh.positions[j] - mesh.positions[i], w = mesh.positions[l] - mesh.positions[i];
      const double cot = std::clamp(dot(u, w) / norm(cross(u, w)), -max_cot, max_cot);
      const Vec3 d = mesh.positions[l] - mesh.positions[j];
      laplace[j] += d * (0.5 * cot);
      laplace[l] += d * (-0.5 * cot);
      area[i] += a / 3;
    }
  }
  const std::vector<Vec3> normals = vertex_normals(mesh);
  std::vector<double> h(nv, 0);
  for (std::size_t v = 0; v < nv; ++v)
    if (area[v] > 0) h[v] = -0.5 * dot(laplace[v] / area[v], normals[v]);
  return h;
}

}  // namespace salient::core
