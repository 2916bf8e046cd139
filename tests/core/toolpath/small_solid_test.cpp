// Small solid regions (PrusaSlicer's solid_infill_below_area): an island of sparse infill no
// larger than the threshold is filled solid; larger islands stay sparse; the area filled does not
// change, only how.
#include <doctest/doctest.h>

#include "core/toolpath/toolpath_generator.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

// Two columns on one bed: a small one (6 × 6 mm) and a large one (20 × 20 mm), 10 mm tall.
Mesh two_columns() {
  Mesh small = salient::test::box(6, 6, 10), large = salient::test::box(20, 20, 10);
  for (Vec3& p : large.positions) p = Vec3{p.x + 15, p.y, p.z};
  const auto offset = static_cast<std::uint32_t>(small.positions.size());
  for (const Vec3& p : large.positions) small.positions.push_back(p);
  for (const Triangle& t : large.triangles)
    small.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return small;
}

struct Totals {
  double solid = 0, sparse = 0;
  int sparse_paths_on_small = 0, sparse_paths_on_large = 0;
};

Totals run(double threshold) {
  std::vector<double> z{0};
  while (z.back() < 10 - 1e-9) z.push_back(z.back() + 0.2);
  ToolpathSettings s;
  s.skirt_distance = 0;
  s.solid_infill_below_area = threshold;
  Totals t;
  for (const LayerToolpaths& layer : generate_toolpaths(two_columns(), z, s)) {
    t.solid += layer.solid_area;
    t.sparse += layer.sparse_area;
    for (const ExtrusionPath& p : layer.paths)
      if (p.role == ExtrusionRole::sparse_infill)
        ++(p.points.front().x < 10 ? t.sparse_paths_on_small : t.sparse_paths_on_large);
  }
  return t;
}

}  // namespace

TEST_CASE("small solid regions: the small column is solid, the large one keeps its sparse infill") {
  const Totals off = run(0), on = run(70);
  CHECK(off.sparse_paths_on_small > 0);
  CHECK(on.sparse_paths_on_small == 0);
  CHECK(on.sparse_paths_on_large > 0);
  CHECK(on.sparse < off.sparse);
  // What was sparse in the small column became solid: the area filled is the same.
  CHECK(on.solid + on.sparse == doctest::Approx(off.solid + off.sparse).epsilon(1e-6));
  // A threshold above the large column's section leaves nothing sparse.
  const Totals all = run(1000);
  CHECK(all.sparse == doctest::Approx(0));
  CHECK(all.sparse_paths_on_large == 0);
}

TEST_CASE("small solid regions: at 100 % or 0 % infill the threshold changes nothing") {
  std::vector<double> z{0};
  while (z.back() < 10 - 1e-9) z.push_back(z.back() + 0.2);
  for (double density : {0.0, 1.0}) {
    ToolpathSettings a, b;
    a.infill_density = b.infill_density = density;
    b.solid_infill_below_area = 70;
    const auto la = generate_toolpaths(two_columns(), z, a), lb = generate_toolpaths(two_columns(), z, b);
    REQUIRE(la.size() == lb.size());
    for (std::size_t i = 0; i < la.size(); ++i) {
      CHECK(la[i].paths.size() == lb[i].paths.size());
      CHECK(la[i].solid_area == doctest::Approx(lb[i].solid_area));
    }
  }
}
