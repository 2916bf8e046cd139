// simplify_mesh and working_mesh: one of the two files that include CGAL (with
// surface_locator.cpp). Our mesh goes in as a polygon soup, is oriented and made manifold by
// CGAL's soup repair, collapsed with Garland–Heckbert plane quadrics, optionally remeshed to
// near-equilateral triangles, and comes back compacted.
#include "core/saliency/mesh_simplifier.hpp"

// GCC 12 reports a false -Wmaybe-uninitialized inside Eigen's fixed 4x4 matrices that CGAL's
// quadrics instantiate; it is not ours to fix.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Edge_collapse_visitor_base.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace salient::core {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace SMS = CGAL::Surface_mesh_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;

// True when CGAL's orient_polygon_soup would leave the soup as it is: no degenerate triangle, every
// directed edge in at most one triangle (so none is reversed and no edge has three), and the
// triangles around each vertex one fan (so no vertex is duplicated). Its own check builds ordered
// maps per vertex (0.2 s of the bunny's 1.3 s simplification); this one is linear.
bool already_oriented_manifold(const Mesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  std::vector<std::uint32_t> start(n + 1, 0);
  for (const Triangle& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return false;
    for (std::uint32_t v : t) ++start[v + 1];
  }
  for (std::size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  // Around each vertex v, each triangle as its corners (prev, next): directed edges prev→v, v→next.
  std::vector<std::array<std::uint32_t, 2>> fan(start[n]);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (const Triangle& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) fan[fill[t[c]]++] = {t[(c + 2) % 3], t[(c + 1) % 3]};
  std::vector<char> seen;
  for (std::size_t v = 0; v < n; ++v) {
    const std::array<std::uint32_t, 2>* f = fan.data() + start[v];
    const std::size_t m = start[v + 1] - start[v];
    for (std::size_t a = 0; a < m; ++a)
      for (std::size_t b = a + 1; b < m; ++b)
        if (f[a][0] == f[b][0] || f[a][1] == f[b][1]) return false;  // a directed edge twice
    if (m == 0) continue;
    // Walk the fan both ways from the first triangle: across v→next to the triangle with prev ==
    // next (unique, as directed edges are), and back; one fan iff the walk meets every triangle.
    seen.assign(m, 0);
    std::size_t visited = 1;
    seen[0] = 1;
    for (int side = 0; side < 2; ++side) {
      std::size_t at = 0;
      for (;;) {
        std::size_t next = m;
        for (std::size_t b = 0; b < m; ++b)
          if (f[b][side] == f[at][1 - side]) next = b;
        if (next == m || seen[next]) break;
        seen[next] = 1;
        ++visited;
        at = next;
      }
    }
    if (visited != m) return false;
  }
  return true;
}

SurfaceMesh surface_of(const Mesh& mesh) {
  std::vector<Point> points;
  points.reserve(mesh.vertex_count());
  for (const Vec3& p : mesh.positions) points.emplace_back(p.x, p.y, p.z);
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(mesh.triangle_count());
  for (const Triangle& t : mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
  // Orienting duplicates vertices where it must to be manifold; a soup it would not change skips it.
  if (!already_oriented_manifold(mesh)) PMP::orient_polygon_soup(points, polygons);
  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  return sm;
}

// Checks the caller's cancel token every 1024 edges costed and collapses: a 100,000-triangle model
// takes seconds here (more under load), one uninterruptible CGAL call otherwise. Throwing out of
// edge_collapse is safe: its queue and edge data are scoped, and the half-collapsed mesh is dropped.
struct CancelVisitor : SMS::Edge_collapse_visitor_base<SurfaceMesh> {
  const RunContext* run = nullptr;
  std::size_t steps = 0;
  void tick() {
    if (++steps % 1024 == 0) run->check();
  }
  void OnCollected(const Profile&, const boost::optional<FT>&) { tick(); }
  void OnCollapsed(const Profile&, const vertex_descriptor&) { tick(); }
};

void collapse(SurfaceMesh& sm, std::size_t target_vertices, const RunContext& run) {
  // Each collapse removes one vertex and three edges; stop at the edge count of the target.
  const std::size_t remove =
      sm.number_of_vertices() > target_vertices ? sm.number_of_vertices() - target_vertices : 0;
  const std::size_t target_edges = sm.number_of_edges() > 3 * remove ? sm.number_of_edges() - 3 * remove : 3;
  SMS::Count_stop_predicate<SurfaceMesh> stop(target_edges);
  SMS::GarlandHeckbert_plane_policies<SurfaceMesh, Kernel> policies(sm);
  CancelVisitor visitor;
  visitor.run = &run;
  SMS::edge_collapse(sm, stop,
                     CGAL::parameters::get_cost(policies.get_cost())
                         .get_placement(policies.get_placement())
                         .visitor(visitor));
  sm.collect_garbage();
}

Mesh mesh_of(const SurfaceMesh& sm) {
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

}  // namespace

Mesh simplify_mesh(const Mesh& mesh, std::size_t target_vertices, const RunContext& run) {
  if (mesh.vertex_count() <= target_vertices) {
    Mesh copy;
    copy.positions = mesh.positions;
    copy.triangles = mesh.triangles;
    return copy;
  }
  SurfaceMesh sm = surface_of(mesh);
  collapse(sm, target_vertices, run);
  return mesh_of(sm);
}

Mesh working_mesh(const Mesh& mesh, std::size_t target_vertices, const RunContext& run) {
  if (mesh.triangle_count() < 4) return simplify_mesh(mesh, target_vertices, run);
  SurfaceMesh sm = surface_of(mesh);
  run.check();
  if (sm.number_of_vertices() > target_vertices) collapse(sm, target_vertices, run);
  run.check();
  // Quadric collapse keeps thin slivers where they fit the surface best; 1/d² weights would turn
  // them into hot spots. Isotropic remeshing at the mean edge length (split above 4/3 of it,
  // collapse below 4/5, flips towards valence 6, tangential relaxation) keeps about the vertex
  // count and the shape, and leaves every edge near that length.
  double total = 0;
  for (SurfaceMesh::Edge_index e : sm.edges())
    total += std::sqrt(CGAL::squared_distance(sm.point(sm.vertex(e, 0)), sm.point(sm.vertex(e, 1))));
  const double target_length = total / std::max<std::size_t>(1, sm.number_of_edges());
  if (target_length > 0) {
    PMP::isotropic_remeshing(faces(sm), target_length, sm, CGAL::parameters::number_of_iterations(3));
    sm.collect_garbage();
  }
  return mesh_of(sm);
}

}  // namespace salient::core
