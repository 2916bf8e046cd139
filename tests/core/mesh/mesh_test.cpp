// Mesh measures: bounds, area, volume and normals on shapes whose answers are known.
#include "core/mesh/mesh.hpp"

#include <doctest/doctest.h>

#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

TEST_CASE("box measures") {
  const Mesh m = salient::test::box(2, 3, 4);
  const BoundingBox b = bounding_box(m);
  CHECK(b.min == Vec3{0, 0, 0});
  CHECK(b.max == Vec3{2, 3, 4});
  CHECK(surface_area(m) == doctest::Approx(2 * (6 + 8 + 12)));
  CHECK(signed_volume(m) == doctest::Approx(24));
}

TEST_CASE("volume is translation invariant and flips sign with orientation") {
  Mesh m = salient::test::box(1, 1, 1);
  for (Vec3& p : m.positions) p += Vec3{1000, -2000, 5};
  CHECK(signed_volume(m) == doctest::Approx(1).epsilon(1e-9));
  for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  CHECK(signed_volume(m) == doctest::Approx(-1).epsilon(1e-9));
}

TEST_CASE("face normals are unit and point outward on a box") {
  const Mesh m = salient::test::box();
  const auto normals = face_normals(m);
  CHECK(normals[0].z == doctest::Approx(-1));  // bottom
  CHECK(normals[2].z == doctest::Approx(1));   // top
  for (const Vec3& n : normals) CHECK(norm(n) == doctest::Approx(1));
}

TEST_CASE("degenerate triangle has a zero normal") {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  m.triangles = {{0, 1, 2}};
  CHECK(norm(unit_normal(m, 0)) == 0);
}
