// convex_hull: one of the files that include CGAL (with core/saliency's). CGAL's quickhull
// (convex_hull_3) into a Surface_mesh, copied back into our Mesh.
#include "core/mesh/convex_hull.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <cmath>
#include <vector>

namespace salient::core {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

}  // namespace

Mesh convex_hull(std::span<const Vec3> points) {
  std::vector<Point> in;
  in.reserve(points.size());
  for (const Vec3& p : points)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) in.emplace_back(p.x, p.y, p.z);
  if (in.size() < 4) return {};
  // Exact predicates: the coplanarity test below and the hull's own are robust.
  bool flat = true;
  std::size_t a = 0, b = 0, c = 0;
  for (std::size_t i = 1; i < in.size() && b == 0; ++i)
    if (in[i] != in[a]) b = i;
  for (std::size_t i = 1; b != 0 && i < in.size() && c == 0; ++i)
    if (!CGAL::collinear(in[a], in[b], in[i])) c = i;
  for (std::size_t i = 1; c != 0 && i < in.size() && flat; ++i)
    flat = CGAL::coplanar(in[a], in[b], in[c], in[i]);
  if (flat) return {};
  SurfaceMesh hull;
  CGAL::convex_hull_3(in.begin(), in.end(), hull);
  Mesh out;
  std::vector<std::uint32_t> index(hull.number_of_vertices() + hull.number_of_removed_vertices());
  for (const auto v : hull.vertices()) {
    const Point& p = hull.point(v);
    index[v.idx()] = static_cast<std::uint32_t>(out.positions.size());
    out.positions.push_back({p.x(), p.y(), p.z()});
  }
  for (const auto f : hull.faces()) {
    Triangle t{};
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      if (k == 3) break;  // convex_hull_3 makes triangles only
      t[static_cast<std::size_t>(k++)] = index[v.idx()];
    }
    if (k == 3) out.triangles.push_back(t);
  }
  return out;
}

}  // namespace salient::core
