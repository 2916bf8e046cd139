// SurfaceLocator: CGAL's AABB tree over the mesh's triangles; barycentric coordinates of the
// closest point are computed here (projected onto the triangle's plane, clamped to it).
#include "core/saliency/surface_locator.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

namespace salient::core {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Triangle3 = Kernel::Triangle_3;
using Iterator = std::vector<Triangle3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Traits = CGAL::AABB_traits<Kernel, Primitive>;

Kernel::Point_3 point(const Vec3& v) {
  return {v.x, v.y, v.z};
}

std::array<double, 3> barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = dot(v0, v0), d01 = dot(v0, v1), d11 = dot(v1, v1), d20 = dot(v2, v0), d21 = dot(v2, v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0)) return {1, 0, 0};
  double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  v = std::clamp(v, 0.0, 1.0);
  w = std::clamp(w, 0.0, 1.0 - v);
  return {1 - v - w, v, w};
}

}  // namespace

struct SurfaceLocator::Tree {
  std::vector<Triangle3> triangles;
  CGAL::AABB_tree<Traits> tree;
};

SurfaceLocator::SurfaceLocator(const Mesh& mesh) : mesh_(mesh), tree_(std::make_unique<Tree>()) {
  tree_->triangles.reserve(mesh.triangle_count());
  for (const Triangle& t : mesh.triangles)
    tree_->triangles.emplace_back(point(mesh.positions[t[0]]), point(mesh.positions[t[1]]),
                                  point(mesh.positions[t[2]]));
  tree_->tree.insert(tree_->triangles.cbegin(), tree_->triangles.cend());
  tree_->tree.accelerate_distance_queries();
}

SurfaceLocator::~SurfaceLocator() = default;

SurfacePoint SurfaceLocator::closest(const Vec3& query) const {
  const auto [p, it] = tree_->tree.closest_point_and_primitive(point(query));
  const auto face = static_cast<std::uint32_t>(it - tree_->triangles.cbegin());
  const Triangle& t = mesh_.triangles[face];
  return {face, barycentric({p.x(), p.y(), p.z()}, mesh_.positions[t[0]], mesh_.positions[t[1]],
                            mesh_.positions[t[2]])};
}

std::vector<double> transfer_values(const Mesh& from, std::span<const double> values, const Mesh& to) {
  const SurfaceLocator locator(from);
  std::vector<double> out(to.vertex_count());
  // Queries on the built tree are const (CGAL locks its lazy builds), each vertex independent.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const SurfacePoint s = locator.closest(to.positions[i]);
                        const Triangle& t = from.triangles[s.face];
                        out[i] = s.barycentric[0] * values[t[0]] + s.barycentric[1] * values[t[1]] +
                                 s.barycentric[2] * values[t[2]];
                      }
                    });
  return out;
}

}  // namespace salient::core
