// Support under overhangs (core/toolpath/support_generator): an upside-down frustum whose wall
// overhangs at θ from vertical gets support when θ is steeper than the support angle (55°), none
// when it is not, and as much under thin layers as under thick ones — at 0.1 mm the old per-layer
// test found each layer's 0.07 mm sliver of overhang and lost it in the 0.6 mm XY gap.
#include "core/toolpath/support_generator.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/geometry/polygon.hpp"
#include "core/pipeline/placed_model.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/slicing/layer_plan.hpp"
#include "core/toolpath/toolpath_generator.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

constexpr double height = 10;  // mm

// A frustum standing on its small end: radius 5 mm on the bed, its wall θ from vertical, 40 sides
// (not so many that the 0.0125 mm section simplification merges them).
Mesh frustum(double theta_degrees) {
  constexpr int sides = 40;
  const double r0 = 5, r1 = r0 + height * std::tan(theta_degrees * M_PI / 180);
  Mesh m;
  for (double r : {r0, r1})
    for (int k = 0; k < sides; ++k) {
      const double a = 2 * M_PI * k / sides;
      m.positions.push_back({r * std::cos(a), r * std::sin(a), r == r0 ? 0.0 : height});
    }
  const auto bottom = static_cast<std::uint32_t>(m.positions.size());
  m.positions.push_back({0, 0, 0});
  m.positions.push_back({0, 0, height});
  for (std::uint32_t k = 0; k < sides; ++k) {
    const std::uint32_t next = (k + 1) % sides;
    m.triangles.push_back({k, next, sides + next});
    m.triangles.push_back({k, sides + next, sides + k});
    m.triangles.push_back({bottom, next, k});
    m.triangles.push_back({bottom + 1, sides + k, sides + next});
  }
  return m;
}

std::vector<double> uniform_z(double h) {
  std::vector<double> z{0};
  while (z.back() < height - 1e-9) z.push_back(std::min(height, z.back() + h));
  return z;
}

// Thicknesses cycling through a plan's mix (0.1..0.3 mm), as an adaptive plan would have them.
std::vector<double> mixed_z() {
  const double mix[] = {0.1, 0.1, 0.2, 0.3, 0.15, 0.1, 0.25, 0.3, 0.1, 0.2};
  std::vector<double> z{0};
  for (std::size_t k = 0; z.back() < height - 1e-9; ++k)
    z.push_back(std::min(height, z.back() + mix[k % 10]));
  return z;
}

// Support volume, mm³ of the extruded lines' swept width × height.
double support_volume(const std::vector<LayerToolpaths>& layers) {
  double v = 0;
  for (const LayerToolpaths& layer : layers)
    for (const ExtrusionPath& p : layer.paths)
      if (p.role == ExtrusionRole::support)
        v += p.length() * p.width * (p.height > 0 ? p.height : layer.height());
  return v;
}

double frustum_support(double theta, const std::vector<double>& z) {
  ToolpathSettings t;
  t.skirt_distance = 0;
  std::vector<LayerToolpaths> layers = generate_toolpaths(frustum(theta), z, t);
  add_support(layers, SupportSettings{});
  return support_volume(layers);
}

}  // namespace

TEST_CASE("support: a frustum steeper than the support angle gets as much under thin layers as thick") {
  for (double theta : {60.0, 65.0, 70.0}) {
    const double v30 = frustum_support(theta, uniform_z(0.3)), v20 = frustum_support(theta, uniform_z(0.2)),
                 v15 = frustum_support(theta, uniform_z(0.15)), v10 = frustum_support(theta, uniform_z(0.1)),
                 mixed = frustum_support(theta, mixed_z());
    INFO("theta " << theta << "°: 0.3 mm " << v30 << ", 0.2 mm " << v20 << ", 0.15 mm " << v15 << ", 0.1 mm "
                  << v10 << ", mixed " << mixed << " mm³");
    CHECK(v30 > 0);
    // Thinner never less (3 %: the lines' grid meets each layer's outline a little differently).
    CHECK(v20 >= 0.97 * v30);
    CHECK(v15 >= 0.97 * v20);
    CHECK(v10 >= 0.97 * v15);
    CHECK(mixed >= 0.97 * std::min({v30, v20, v15, v10}));
  }
}

TEST_CASE("support: a frustum within the support angle gets none, at any layer height") {
  for (double theta : {50.0, 53.0})
    for (const std::vector<double>& z :
         {uniform_z(0.3), uniform_z(0.2), uniform_z(0.15), uniform_z(0.1), mixed_z()}) {
      INFO("theta " << theta << "°, " << z.size() - 1 << " layers");
      CHECK(frustum_support(theta, z) == 0);
    }
}

namespace {

// A model in two halves across x = 0, the −x half printed at `fine` mm, the +x half at `coarse`
// (a segmented plan's regions, paper §5), with support.
std::vector<LayerToolpaths> two_regions(const Mesh& mesh, double fine, double coarse) {
  std::vector<float> saliency(mesh.vertex_count(), 1.0f);
  const ZProfile p = ZProfile::build(mesh, saliency, SlicingParams{0.1, 0.3, 0.01});
  const auto every = [&](double h) {
    LayerPlan plan;
    const int step = static_cast<int>(std::lround(h / 0.01));
    for (int b = 0; b < p.cells(); b += step) plan.boundaries.push_back(b);
    plan.boundaries.push_back(p.cells());
    return plan;
  };
  PlanRegion left, right;
  left.side = 0, right.side = 1;
  left.last_cell = right.last_cell = p.cells();
  left.clip = {{-100, -100}, {0, -100}, {0, 100}, {-100, 100}};
  right.clip = {{0, -100}, {100, -100}, {100, 100}, {0, 100}};
  left.plan = every(fine), right.plan = every(coarse);
  RegionSliceSettings s;
  s.toolpaths.skirt_distance = 0;
  s.support = true;
  return region_toolpaths(mesh, p, {left, right}, s);
}

}  // namespace

TEST_CASE("support: a segmented plan's coarse region is part of every printed layer it spans") {
  // A box has no overhang. Printed layers merged from a 0.1 mm half and a 0.3 mm half hold the
  // coarse half only every third layer: compared layer with merged layer, the coarse half looked
  // like an overhang, and support was printed inside it.
  Mesh box = salient::test::box(20, 20, 6);
  for (Vec3& v : box.positions) v = Vec3{v.x - 10, v.y - 10, v.z};
  CHECK(support_volume(two_regions(box, 0.1, 0.3)) == 0);
  // The frustum cut in the same halves gets its support, as much as sliced whole.
  const double whole = frustum_support(65, uniform_z(0.3)),
               cut = support_volume(two_regions(frustum(65), 0.1, 0.3));
  INFO("whole at 0.3 mm " << whole << " mm³, halves at 0.1 and 0.3 mm " << cut << " mm³");
  CHECK(cut >= 0.97 * whole);
  CHECK(cut <= 1.1 * frustum_support(65, uniform_z(0.1)));
}

namespace {

// A shared model placed as `slice` places it (80 mm tall, up y) and sliced through the pipeline's
// toolpaths at uniform `h` mm, with support: its support volume.
double model_support(const std::string& name, double h) {
  MeshOptions o;
  o.model = salient::test::model_path(name);
  o.up = "y";
  o.height = 80;
  const PlacedModel placed = load_placed(o);
  const Mesh& mesh = placed.loaded.mesh;
  const std::vector<float> saliency(mesh.vertex_count(), 1.0f);
  const ZProfile p = ZProfile::build(mesh, saliency, SlicingParams{0.1, 0.3, 0.01});
  PlanRegion whole;
  whole.last_cell = p.cells();
  whole.plan = uniform_plan(p, static_cast<int>(std::lround(p.height() / h)));
  RegionSliceSettings s;
  s.toolpaths.skirt_distance = 0;
  s.support = true;
  return support_volume(region_toolpaths(mesh, p, {whole}, s));
}

}  // namespace

TEST_CASE("support: the bunny and suzanne at 80 mm get no less support at 0.1 mm than at 0.2 mm") {
  for (const char* name : {"stanford-bunny.obj", "suzanne.obj"}) {
    const double v20 = model_support(name, 0.2), v10 = model_support(name, 0.1);
    INFO(std::string(name) << ": 0.2 mm " << v20 << " mm³, 0.1 mm " << v10 << " mm³");
    CHECK(v20 > 0);
    CHECK(v10 >= 0.97 * v20);
  }
}
