// Mesh sections and polygon areas on shapes with known cross-sections.
#include "core/geometry/mesh_section.hpp"

#include <doctest/doctest.h>

#include "core/geometry/polygon_ops.hpp"
#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

TEST_CASE("a box's section is its footprint, counter-clockwise") {
  const Mesh box = salient::test::box(4, 3, 2);
  const std::vector<double> z = {1.0, 0.5, 2.0 - 1e-9};
  const auto sections = section_mesh(box, z);
  for (const Section& s : sections) {
    REQUIRE(s.loops.size() == 1);
    CHECK(s.open_chains == 0);
    CHECK(signed_area(s.loops[0]) == doctest::Approx(12));
  }
}

TEST_CASE("a pyramid's section shrinks with the square of the height left") {
  const Mesh pyr = salient::test::pyramid(10, 5);
  const std::vector<double> z = {2.5};
  const auto s = section_mesh(pyr, z);
  CHECK(covered_area(s[0].loops) == doctest::Approx(25).epsilon(1e-6));
  const std::vector<double> z0 = {1e-6};
  CHECK(xor_area(section_mesh(pyr, z0)[0].loops, s[0].loops) == doctest::Approx(75).epsilon(1e-4));
}

TEST_CASE("an open box's section is an open chain, closed only when allowed") {
  Mesh open = salient::test::box(4, 3, 2);
  open.triangles.erase(open.triangles.begin() + 6, open.triangles.begin() + 8);  // no +x wall
  const std::vector<double> z = {1.0};
  const auto strict = section_mesh(open, z, {0.5});
  CHECK(strict[0].loops.empty());
  CHECK(strict[0].open_chains == 1);
  const auto closing = section_mesh(open, z, {10.0});
  REQUIRE(closing[0].loops.size() == 1);
  CHECK(closing[0].gaps_closed == 1);
  CHECK(signed_area(closing[0].loops[0]) == doctest::Approx(12));
}

TEST_CASE("a box with a hole gives an outer ring and a hole, netting their difference") {
  Polygons ring = {{{0, 0}, {10, 0}, {10, 10}, {0, 10}}, {{2, 2}, {2, 8}, {8, 8}, {8, 2}}};
  CHECK(covered_area(ring) == doctest::Approx(64));
  CHECK(union_ex(ring).size() == 1);
  CHECK(union_ex(ring)[0].holes.size() == 1);
}
