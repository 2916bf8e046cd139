// Planar regions: a box's six faces; a flat base found whatever its tessellation; none on a sphere.
#include "core/orient/planar_regions.hpp"

#include <doctest/doctest.h>

#include <cmath>

#include "tests/core/mesh/mesh_test_util.hpp"
#include "tests/core/orient/test_solids.hpp"

using namespace salient::core;

TEST_CASE("a box has six planar regions, its faces, largest first") {
  const Mesh box = salient::test::box(10, 20, 30);
  const auto regions = planar_regions(box, 3 * M_PI / 180, 0.01);
  REQUIRE(regions.size() == 6);
  CHECK(regions[0].area == doctest::Approx(600));
  CHECK(std::abs(regions[0].normal.x) == doctest::Approx(1));
  CHECK(regions[5].area == doctest::Approx(200));
  CHECK(std::abs(regions[5].normal.z) == doctest::Approx(1));
  for (const PlanarRegion& r : regions) CHECK(r.faces.size() == 2);
  // The bottom: the box's centre of mass stands over it.
  const PlanarRegion& bottom = regions[4].normal.z < 0 ? regions[4] : regions[5];
  CHECK(projects_inside(box, bottom, {5, 10, 15}));
  CHECK(!projects_inside(box, bottom, {11, 10, 15}));
}

TEST_CASE("a block's flat bottom is one region, its curved top is not one") {
  const Mesh block = salient::test::ramp_block();  // 60 × 30, the top curving up 10 mm
  const auto regions = planar_regions(block, 10 * M_PI / 180, 0.2);
  REQUIRE(!regions.empty());
  CHECK(regions[0].area == doctest::Approx(1800));
  CHECK(regions[0].normal.z == doctest::Approx(-1));
  CHECK(regions[0].faces.size() == 2 * 30 * 15);
  for (std::size_t i = 1; i < regions.size(); ++i) CHECK(regions[i].area < 0.5 * 1800);
}

TEST_CASE("a sphere has no large planar region, and a fold is not flat") {
  Mesh sphere = salient::test::uv_sphere(48, 96);
  for (Vec3& p : sphere.positions) p = p * 40;
  const auto regions = planar_regions(sphere, 10 * M_PI / 180, 0.2);
  CHECK(regions.front().area < 0.01 * surface_area(sphere));
  // Two faces meeting at 27° (the second rises 20° along each axis): two regions at 10°, one at 30°.
  Mesh fold;
  fold.positions = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {10, 10, 10 * std::tan(20 * M_PI / 180)}};
  fold.triangles = {{0, 1, 2}, {1, 3, 2}};
  CHECK(planar_regions(fold, 10 * M_PI / 180, 10).size() == 2);
  CHECK(planar_regions(fold, 30 * M_PI / 180, 10).size() == 1);
}
