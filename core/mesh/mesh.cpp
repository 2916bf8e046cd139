// Mesh measures: bounds, area, volume, normals.
#include "core/mesh/mesh.hpp"

#include <algorithm>
#include <limits>

namespace salient::core {

BoundingBox bounding_box(const Mesh& mesh) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  BoundingBox box{{inf, inf, inf}, {-inf, -inf, -inf}};
  auto grow = [&box](const Vec3& p) {
    box.min = {std::min(box.min.x, p.x), std::min(box.min.y, p.y), std::min(box.min.z, p.z)};
    box.max = {std::max(box.max.x, p.x), std::max(box.max.y, p.y), std::max(box.max.z, p.z)};
  };
  if (mesh.triangles.empty()) {
    for (const Vec3& p : mesh.positions) grow(p);
  } else {
    for (const Triangle& t : mesh.triangles)
      for (std::uint32_t v : t) grow(mesh.positions[v]);
  }
  if (box.min.x > box.max.x) return {};
  return box;
}

Vec3 area_normal(const Mesh& mesh, std::size_t t) {
  const Triangle& tri = mesh.triangles[t];
  const Vec3& a = mesh.positions[tri[0]];
  return cross(mesh.positions[tri[1]] - a, mesh.positions[tri[2]] - a);
}

Vec3 unit_normal(const Mesh& mesh, std::size_t t) {
  const Vec3 n = area_normal(mesh, t);
  const double len = norm(n);
  return len > 0 ? n / len : Vec3{};
}

std::vector<Vec3> face_normals(const Mesh& mesh) {
  std::vector<Vec3> normals(mesh.triangles.size());
  for (std::size_t t = 0; t < normals.size(); ++t) normals[t] = unit_normal(mesh, t);
  return normals;
}

double surface_area(const Mesh& mesh) {
  double area = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) area += 0.5 * norm(area_normal(mesh, t));
  return area;
}

double signed_volume(const Mesh& mesh) {
  // Sum of signed tetrahedra against a point near the mesh (its bounds' centre) rather than the
  // origin, which keeps the sum well conditioned for models far from the origin.
  const Vec3 o = bounding_box(mesh).center();
  double six_v = 0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a = mesh.positions[t[0]] - o;
    const Vec3 b = mesh.positions[t[1]] - o;
    const Vec3 c = mesh.positions[t[2]] - o;
    six_v += dot(a, cross(b, c));
  }
  return six_v / 6.0;
}

}  // namespace salient::core
