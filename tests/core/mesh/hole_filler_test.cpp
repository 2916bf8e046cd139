// Hole filling (issue 32 item 9): caps close open bottoms and sockets without adding vertices, face
// outward, leave closed meshes and ambiguous holes alone, and are not part of the file's surface.
#include "core/mesh/hole_filler.hpp"

#include <doctest/doctest.h>

#include <cmath>

#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/mesh_repair.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;
using salient::test::box;
using salient::test::uv_sphere;

namespace {

double area(const Mesh& m, std::size_t from) {
  double a = 0;
  for (std::size_t f = from; f < m.triangles.size(); ++f) {
    const Triangle& t = m.triangles[f];
    a += 0.5 * norm(cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]));
  }
  return a;
}

// An L-shaped prism (area 3, height 1) without its top: a non-convex hole.
Mesh open_l_prism() {
  const double xy[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  Mesh m;
  for (int z = 0; z < 2; ++z)
    for (const auto& p : xy) m.positions.push_back({p[0], p[1], double(z)});
  for (std::uint32_t i = 1; i + 1 < 6; ++i) m.triangles.push_back({0, i + 1, i});  // bottom, facing down
  for (std::uint32_t i = 0; i < 6; ++i) {
    const std::uint32_t j = (i + 1) % 6;
    m.triangles.push_back({i, j, j + 6});
    m.triangles.push_back({i, j + 6, i + 6});
  }
  return m;
}

}  // namespace

TEST_CASE("an open box is capped outward with two faces and no new vertex") {
  Mesh m = box(2, 3, 4);
  m.triangles.resize(10);  // the side at x = 0 is gone
  const HoleFilling f = fill_holes(m);
  CHECK(f.holes_filled == 1);
  CHECK(f.faces_added == 2);
  CHECK(f.holes_left == 0);
  CHECK(m.vertex_count() == 8);
  CHECK(signed_volume(m) == doctest::Approx(24));
}

TEST_CASE("a non-convex hole is ear-clipped inside its outline") {
  Mesh m = open_l_prism();
  const std::size_t before = m.triangles.size();
  const HoleFilling f = fill_holes(m);
  REQUIRE(f.holes_filled == 1);
  CHECK(f.faces_added == 4);                     // a hexagon: n - 2 triangles
  CHECK(area(m, before) == doctest::Approx(3));  // no cap triangle outside the L (it would add area)
  CHECK(signed_volume(m) == doctest::Approx(3));
  CHECK(repair_mesh(m).watertight);
}

TEST_CASE("repair closes a non-planar hole of an inside-out sphere, then reports it watertight") {
  Mesh m = uv_sphere(16, 24);
  for (Triangle& t : m.triangles) std::swap(t[1], t[2]);  // inside out
  const double full = -signed_volume(m);
  // A patch across the equator: its rim is not planar.
  std::vector<Triangle> kept;
  for (const Triangle& t : m.triangles) {
    const Vec3 c = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3;
    if (!(c.x > 0.8 && std::abs(c.z) < 0.4)) kept.push_back(t);
  }
  REQUIRE(kept.size() < m.triangles.size());
  m.triangles = kept;
  const std::size_t vertices = m.vertex_count();
  const RepairReport r = repair_mesh(m);
  CHECK(r.holes_filled == 1);
  CHECK(r.cap_faces > 0);
  CHECK(r.boundary_edges == 0);
  CHECK(r.watertight);
  CHECK(m.vertex_count() <= vertices);    // those inside the patch went, none came
  CHECK(signed_volume(m) > 0.97 * full);  // outward, and the cap is close to the missing patch
  CHECK(signed_volume(m) < full);
}

TEST_CASE("a closed mesh gets nothing, and two holes through one vertex are left open") {
  Mesh closed = box();
  CHECK(fill_holes(closed).faces_added == 0);
  CHECK(closed.triangle_count() == 12);

  // Two faces of a box's corner fan removed where they touch only at vertex 2: a pinch.
  Mesh pinched = box();
  pinched.triangles.erase(pinched.triangles.begin() + 9);  // {2, 7, 6}
  pinched.triangles.erase(pinched.triangles.begin() + 0);  // {0, 2, 1}
  const HoleFilling f = fill_holes(pinched);
  CHECK(f.holes_filled == 0);
  CHECK(f.holes_left >= 1);
  CHECK(pinched.triangle_count() == 10);
}

TEST_CASE("loose triangles are no holes: each would be capped by itself reversed") {
  Mesh m;
  for (int i = 0; i < 50; ++i) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.push_back({3.0 * i, 0, 0});
    m.positions.push_back({3.0 * i + 1, 0, 0});
    m.positions.push_back({3.0 * i, 1, 0.5});
    m.triangles.push_back({base, base + 1, base + 2});
  }
  const HoleFilling f = fill_holes(m);
  CHECK(f.holes_filled == 0);
  CHECK(f.holes_left == 50);
  CHECK(m.triangle_count() == 50);
}

TEST_CASE("the file's surface is the mesh without its caps, and per-vertex colours still fit") {
  Mesh m = box();
  m.triangles.resize(10);
  m.colors.assign(m.vertex_count(), Color{});
  MeshFile file{};
  file.mesh = m;
  const LoadedMesh loaded = repair_loaded(file, "open-box.obj");
  CHECK(loaded.repair.holes_filled == 1);
  CHECK(loaded.mesh.triangle_count() == 12);
  CHECK(loaded.mesh.colors.size() == loaded.mesh.vertex_count());
  const Mesh surface = file_surface(loaded);
  CHECK(surface.triangle_count() == 10);
  CHECK(surface.vertex_count() == loaded.mesh.vertex_count());

  RepairOptions off;
  off.fill_holes = false;
  Mesh kept_open = box();
  kept_open.triangles.resize(10);
  const RepairReport r = repair_mesh(kept_open, off);
  CHECK(r.holes_filled == 0);
  CHECK(r.boundary_edges == 4);
}
