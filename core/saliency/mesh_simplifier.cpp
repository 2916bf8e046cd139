// simplify_mesh: one of the two files that include CGAL (with surface_locator.cpp). Our mesh
// goes in as a polygon soup, is oriented and made manifold by CGAL's soup repair, collapsed with
// Garland–Heckbert plane quadrics, and comes back compacted.
#include "core/saliency/mesh_simplifier.hpp"

// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen's fixed 4x4 matrices that CGAL's
// quadrics instantiate; it is not ours to fix.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <unordered_map>

namespace salient::core {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace SMS = CGAL::Surface_mesh_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;

}  // namespace

Mesh simplify_mesh(const Mesh& mesh, std::size_t target_vertices) {
  if (mesh.vertex_count() <= target_vertices) {
    Mesh copy;
    copy.positions = mesh.positions;
    copy.triangles = mesh.triangles;
    return copy;
  }
  std::vector<Point> points;
  points.reserve(mesh.vertex_count());
  for (const Vec3& p : mesh.positions) points.emplace_back(p.x, p.y, p.z);
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(mesh.triangle_count());
  for (const Triangle& t : mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
  PMP::orient_polygon_soup(points, polygons);  // duplicates vertices where it must to be manifold
  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);

  // Each collapse removes one vertex and three edges; stop at the edge count of the target.
  const std::size_t remove =
      sm.number_of_vertices() > target_vertices ? sm.number_of_vertices() - target_vertices : 0;
  const std::size_t target_edges = sm.number_of_edges() > 3 * remove ? sm.number_of_edges() - 3 * remove : 3;
  SMS::Count_stop_predicate<SurfaceMesh> stop(target_edges);
  SMS::GarlandHeckbert_plane_policies<SurfaceMesh, Kernel> policies(sm);
  SMS::edge_collapse(sm, stop,
                     CGAL::parameters::get_cost(policies.get_cost()).get_placement(policies.get_placement()));
  sm.collect_garbage();

  Mesh out;
  out.positions.reserve(sm.number_of_vertices());
  for (SurfaceMesh::Vertex_index v : sm.vertices()) {
    const Point& p = sm.point(v);
    out.positions.push_back({p.x(), p.y(), p.z()});
  }
  out.triangles.reserve(sm.number_of_faces());
  for (SurfaceMesh::Face_index f : sm.faces()) {
    Triangle t{};
    int k = 0;
    for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
      if (k < 3) t[k] = static_cast<std::uint32_t>(v.idx());
      ++k;
    }
    if (k == 3) out.triangles.push_back(t);
  }
  return out;
}

}  // namespace salient::core
