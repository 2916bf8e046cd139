// simplify_mesh: a soup CGAL's orientation would leave as it is skips that pass, and must come out
// exactly as if it had gone through it; soups that need it (a flipped triangle, a vertex shared by
// two surfaces) still go through it.
#include "core/saliency/mesh_simplifier.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

// A UV sphere with its vertices pushed in and out a little, so that no two collapse costs tie.
Mesh bumpy_sphere(int rings, int segments) {
  Mesh m = salient::test::uv_sphere(rings, segments);
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    m.positions[i] = m.positions[i] * (1 + 0.02 * std::sin(7.0 * i));
  return m;
}

bool same_mesh(const Mesh& a, const Mesh& b) {
  if (a.triangles != b.triangles || a.positions.size() != b.positions.size()) return false;
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    if (a.positions[i].x != b.positions[i].x || a.positions[i].y != b.positions[i].y ||
        a.positions[i].z != b.positions[i].z)
      return false;
  return true;
}

// Every directed edge in at most one triangle: consistently oriented and edge-manifold.
bool consistently_oriented(const Mesh& m) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
  for (const Triangle& t : m.triangles)
    for (int c = 0; c < 3; ++c)
      if (!directed.insert({t[c], t[(c + 1) % 3]}).second) return false;
  return true;
}

}  // namespace

TEST_CASE("a soup that needs no orienting simplifies as one that CGAL re-orients to it") {
  const Mesh clean = bumpy_sphere(30, 60);
  for (std::size_t flipped : {std::size_t(1), clean.triangles.size() / 2, clean.triangles.size() - 1}) {
    Mesh soup = clean;
    std::reverse(soup.triangles[flipped].begin(), soup.triangles[flipped].end());
    for (std::size_t target : {std::size_t(200), std::size_t(1000)}) {
      const Mesh a = simplify_mesh(clean, target), b = simplify_mesh(soup, target);
      CHECK(same_mesh(a, b));
      CHECK(consistently_oriented(a));
      CHECK(a.vertex_count() <= target + 2);
    }
  }
}

TEST_CASE("two surfaces sharing a vertex are split and simplified") {
  Mesh m = bumpy_sphere(20, 40);
  const Mesh other = bumpy_sphere(20, 40);
  const auto offset = static_cast<std::uint32_t>(m.positions.size() - 1);
  // The second sphere's south pole (vertex 0) is the first one's north pole (the last vertex).
  for (std::size_t i = 1; i < other.positions.size(); ++i)
    m.positions.push_back(other.positions[i] + Vec3{0, 0, 2});
  for (Triangle t : other.triangles) {
    for (std::uint32_t& v : t) v = v == 0 ? offset : v + offset;
    m.triangles.push_back(t);
  }
  const Mesh out = simplify_mesh(m, 300);
  CHECK(out.vertex_count() >= 250);
  CHECK(out.vertex_count() <= 310);
  CHECK(consistently_oriented(out));
  for (const Triangle& t : out.triangles)
    for (std::uint32_t v : t) CHECK(v < out.vertex_count());
}

// A large model's collapse is one CGAL call of seconds (a running job's cancel took 12 s on a loaded
// sanitizer build): the token is checked inside it, not only before and after.
TEST_CASE("a cancelled token stops the edge collapse from inside it") {
  const Mesh m = bumpy_sphere(100, 200);  // 19,802 vertices: the collapse costs every edge first
  CancelToken token;
  token.cancel();
  RunContext run;
  run.cancel = &token;
  // simplify_mesh checks nowhere but inside the collapse.
  CHECK_THROWS_AS(simplify_mesh(m, 500, run), Cancelled);
  CHECK_THROWS_AS(working_mesh(m, 500, run), Cancelled);
  CHECK(simplify_mesh(m, 500).vertex_count() <= 520);
}
