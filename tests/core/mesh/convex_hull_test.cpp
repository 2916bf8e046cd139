// convex_hull: a closed, outward-facing hull of the points' extremes; nothing for a flat set.
#include "core/mesh/convex_hull.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

TEST_CASE("the hull of a box and points inside it is the box") {
  Mesh box = salient::test::box(10, 20, 30);
  std::vector<Vec3> points = box.positions;
  for (int i = 1; i < 10; ++i) points.push_back({i * 1.0, i * 2.0, i * 3.0});  // inside
  points.push_back({5, 20, 15});                                               // on a face
  const Mesh hull = convex_hull(points);
  CHECK(hull.vertex_count() == 8);
  CHECK(hull.triangle_count() == 12);
  CHECK(signed_volume(hull) == doctest::Approx(6000));  // positive: outward-facing
  CHECK(surface_area(hull) == doctest::Approx(surface_area(box)));
}

TEST_CASE("the hull of a sphere's vertices has the sphere's vertices, and a non-convex mesh's is larger") {
  const Mesh sphere = salient::test::uv_sphere(16, 32);
  const Mesh hull = convex_hull(sphere.positions);
  CHECK(hull.vertex_count() == sphere.vertex_count());
  CHECK(signed_volume(hull) == doctest::Approx(signed_volume(sphere)));
  // An L of two boxes: its hull fills the notch.
  std::vector<Vec3> ell = salient::test::box(30, 10, 10).positions;
  for (const Vec3& p : salient::test::box(10, 10, 30).positions) ell.push_back(p);
  CHECK(signed_volume(convex_hull(ell)) == doctest::Approx(3000 + 3000 - 1000 + 0.5 * 20 * 20 * 10));
}

TEST_CASE("points that span no volume have no hull") {
  CHECK(convex_hull(std::vector<Vec3>{}).triangle_count() == 0);
  CHECK(convex_hull(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}).triangle_count() == 0);
  CHECK(convex_hull(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {3, 2, 0}})
            .triangle_count() == 0);
  CHECK(convex_hull(std::vector<Vec3>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}).triangle_count() == 0);
  CHECK(convex_hull(std::vector<Vec3>{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}).triangle_count() == 0);
  const Vec3 nan{std::nan(""), 0, 0};
  CHECK(convex_hull(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, nan}).triangle_count() == 0);
  CHECK(convex_hull(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, nan}).triangle_count() ==
        4);
}
