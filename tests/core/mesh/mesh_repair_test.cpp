// Repair: welding, degenerate and duplicate faces, boundary and non-manifold edges,
// orientation (consistent, outward for closed parts, impossible on a Möbius strip).
#include "core/mesh/mesh_repair.hpp"

#include <doctest/doctest.h>

#include <cmath>

#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;
using salient::test::box;

TEST_CASE("a clean box needs no repair and is watertight") {
  Mesh m = box();
  const RepairReport r = repair_mesh(m);
  CHECK(r.watertight);
  CHECK(r.components == 1);
  CHECK(r.lines().empty());
  CHECK(m.triangle_count() == 12);
}

TEST_CASE("STL-style soup is welded into a closed box") {
  const Mesh indexed = box();
  Mesh soup;
  for (const Triangle& t : indexed.triangles) {
    Triangle s{};
    for (int k = 0; k < 3; ++k) {
      s[k] = static_cast<std::uint32_t>(soup.positions.size());
      // jitter below the weld tolerance, as float round-trips leave it
      soup.positions.push_back(indexed.positions[t[k]] + Vec3{1e-9 * k, 0, 0});
    }
    soup.triangles.push_back(s);
  }
  const RepairReport r = repair_mesh(soup);
  CHECK(r.vertices_welded == 36 - 8);
  CHECK(soup.vertex_count() == 8);
  CHECK(r.watertight);
}

TEST_CASE("degenerate and duplicate faces are removed") {
  Mesh m = box();
  m.positions.push_back({0.5, 0, 0});  // on the edge 0-1
  m.triangles.push_back({0, 1, 8});    // zero area
  m.triangles.push_back({3, 3, 2});    // repeated vertex
  m.triangles.push_back({2, 1, 0});    // same as {0, 2, 1}
  m.triangles.push_back({0, 1, 2});    // same vertices, opposite orientation
  const RepairReport r = repair_mesh(m);
  CHECK(r.degenerate_faces_removed == 2);
  CHECK(r.duplicate_faces_removed == 2);
  CHECK(r.unused_vertices_removed == 1);
  CHECK(m.triangle_count() == 12);
  CHECK(r.watertight);
}

TEST_CASE("flipped faces are made consistent, and an inside-out box turned outward") {
  Mesh m = box();
  std::swap(m.triangles[3][1], m.triangles[3][2]);
  std::swap(m.triangles[7][1], m.triangles[7][2]);
  RepairReport r = repair_mesh(m);
  CHECK(r.faces_flipped == 2);
  CHECK(signed_volume(m) == doctest::Approx(1));

  Mesh inside_out = box();
  for (Triangle& t : inside_out.triangles) std::swap(t[1], t[2]);
  r = repair_mesh(inside_out);
  CHECK(r.faces_flipped == 12);
  CHECK(signed_volume(inside_out) == doctest::Approx(1));
}

TEST_CASE("an open box reports its boundary, a fin a non-manifold edge") {
  Mesh open = box();
  open.triangles.resize(10);  // no side at x = 0
  RepairOptions keep_open;
  keep_open.fill_holes = false;  // hole_filler_test.cpp: filled, it is watertight
  RepairReport r = repair_mesh(open, keep_open);
  CHECK_FALSE(r.watertight);
  CHECK(r.boundary_edges == 4);

  Mesh fin = box();
  fin.positions.push_back({0.5, -1, 0.5});
  fin.triangles.push_back({0, 1, 8});  // third face on the edge 0-1
  r = repair_mesh(fin);
  CHECK(r.non_manifold_edges == 1);
  CHECK(r.boundary_edges == 2);
  CHECK_FALSE(r.watertight);
}

TEST_CASE("a Möbius strip is reported as non-orientable") {
  Mesh m;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, w = 0.3;
    for (int s : {-1, 1}) {
      const double r = 1 + s * w * std::cos(a / 2);
      m.positions.push_back({r * std::cos(a), r * std::sin(a), s * w * std::sin(a / 2)});
    }
  }
  for (int i = 0; i < n; ++i) {
    const std::uint32_t a = 2 * i, b = 2 * i + 1;
    // the last quad joins with a half twist: its ends swap sides
    const std::uint32_t c = i + 1 < n ? 2 * (i + 1) : 1, d = i + 1 < n ? 2 * (i + 1) + 1 : 0;
    m.triangles.push_back({a, b, d});
    m.triangles.push_back({a, d, c});
  }
  const RepairReport r = repair_mesh(m);
  CHECK_FALSE(r.orientable);
  CHECK(r.boundary_edges > 0);
}

TEST_CASE("two separate boxes are two components, each outward") {
  Mesh m = box();
  Mesh other = box();
  for (Triangle& t : other.triangles) {
    for (std::uint32_t& v : t) v += 8;
    std::swap(t[1], t[2]);  // inside out
  }
  for (Vec3& p : other.positions) m.positions.push_back(p + Vec3{5, 0, 0});
  m.triangles.insert(m.triangles.end(), other.triangles.begin(), other.triangles.end());
  const RepairReport r = repair_mesh(m);
  CHECK(r.components == 2);
  CHECK(r.faces_flipped == 12);
  CHECK(signed_volume(m) == doctest::Approx(2));
}
