// Placement: up axis, scaling to a height or by a factor, z = 0 and bed centring.
#include "core/mesh/placement.hpp"

#include <doctest/doctest.h>

#include "core/common/input_error.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;
using salient::test::box;

TEST_CASE("y-up model is stood up, scaled to 80 mm and centred") {
  Mesh m = box(2, 4, 1);  // tallest along y
  for (Vec3& p : m.positions) p += Vec3{10, 20, 30};
  PlacementOptions o;
  o.up = UpAxis::y;
  o.target_height = 80;
  o.bed_center_x = 100;
  o.bed_center_y = 50;
  const Placement p = place_mesh(m, o);
  CHECK(p.scale == doctest::Approx(20));
  CHECK(p.bounds.min.z == 0);
  CHECK(p.bounds.max.z == doctest::Approx(80));
  CHECK(p.bounds.size().x == doctest::Approx(40));
  CHECK(p.bounds.size().y == doctest::Approx(20));
  CHECK(p.bounds.center().x == doctest::Approx(100));
  CHECK(p.bounds.center().y == doctest::Approx(50));
  CHECK(signed_volume(m) == doctest::Approx(2 * 4 * 1 * 8000));  // proper rotation keeps the sign
}

TEST_CASE("x-up and a scale factor") {
  Mesh m = box(3, 1, 1);
  PlacementOptions o;
  o.up = UpAxis::x;
  o.scale = 2;
  const Placement p = place_mesh(m, o);
  CHECK(p.bounds.size().z == doctest::Approx(6));
  CHECK(signed_volume(m) == doctest::Approx(24));
}

TEST_CASE("impossible placements are errors naming the option") {
  Mesh m = box();
  PlacementOptions o;
  o.target_height = -1;
  CHECK_THROWS_WITH_AS(place_mesh(m, o), "placement: height must be a positive number of millimetres",
                       InputError);
  o.target_height = 10;
  o.scale = 2;
  CHECK_THROWS_WITH_AS(place_mesh(m, o), "placement: give either height or scale, not both", InputError);
  Mesh flat;
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  flat.triangles = {{0, 1, 2}};
  PlacementOptions h;
  h.target_height = 80;
  CHECK_THROWS_AS(place_mesh(flat, h), InputError);
  CHECK(parse_up_axis("y") == UpAxis::y);
  CHECK_FALSE(parse_up_axis("up").has_value());
}
