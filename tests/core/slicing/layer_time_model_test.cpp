// LayerTimeModel: exact sections of shapes with known perimeters and areas, the skin rule at the
// bed and the top, the windows' consistency, and times that grow with what a layer prints.
#include "core/slicing/layer_time_model.hpp"

#include <doctest/doctest.h>

#include <random>

#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

namespace {

ZProfile profile_of(const Mesh& mesh) {
  return ZProfile::build(mesh, std::vector<float>(mesh.vertex_count(), 1.0f), {});
}

}  // namespace

TEST_CASE("layer time model: a box's walls are its perimeter, its skins the whole section near the ends") {
  const Mesh mesh = salient::test::box(20, 10, 10);
  const ZProfile profile = profile_of(mesh);
  TimeModelParams params;
  params.walls = 3;
  const LayerTimeModel model(mesh, profile, params);
  const double w = params.line_width;
  // Mid-height: no surface within the skin thickness, sparse infill only.
  const LayerFeatures mid = model.features(500, 510);
  CHECK(mid.wall_length == doctest::Approx(3 * 60.0));
  CHECK(mid.solid_length == doctest::Approx(0).epsilon(1e-9));
  const double spacing = w - 0.1 * (1 - M_PI / 4);
  const double inner = 200 - 3 * spacing * 60;
  const double group = 3;  // ⌊0.3 / 0.1⌋ layers share one sparse pass
  CHECK(mid.sparse_length ==
        doctest::Approx(inner / ((w - group * 0.1 * (1 - M_PI / 4)) / params.infill_density) / group));
  // Within the bottom thickness of the bed, and under the top: all solid.
  for (const LayerFeatures& f : {model.features(0, 10), model.features(990, 1000)}) {
    CHECK(f.sparse_length == 0);
    CHECK(f.solid_length == doctest::Approx(inner / spacing));
  }
  CHECK(model.features(0, 10).first);
  CHECK_FALSE(mid.first);
}

TEST_CASE("layer time model: a pyramid's section shrinks as (1 - z/h)^2") {
  const Mesh mesh = salient::test::pyramid(20, 10);
  const ZProfile profile = profile_of(mesh);
  TimeModelParams params;
  params.walls = 1;
  const LayerTimeModel model(mesh, profile, params);
  for (int k : {100, 250, 500, 800}) {
    CAPTURE(k);
    const double z = (k + 0.5) * profile.grid(), side = 20 * (1 - z / 10);
    // features(k, k + 1) cuts at the mid-plane of cell k.
    CHECK(model.features(k, k + 1).wall_length == doctest::Approx(4 * side).epsilon(1e-9));
  }
}

TEST_CASE("layer time model: a window costs each layer as the whole model does") {
  std::mt19937 rng(5);
  const Mesh mesh = salient::test::random_blob(rng, 12, 16, 12);
  const ZProfile profile = profile_of(mesh);
  const LayerTimeModel whole(mesh, profile);
  const int first = 20;
  const LayerTimeModel above = whole.window(first, profile.cells());
  CHECK(above.cells() == profile.cells() - first);
  std::uniform_int_distribution<int> at(0, above.cells() - 40), width(10, 40);
  for (int trial = 0; trial < 200; ++trial) {
    const int i = at(rng), j = i + width(rng);
    CHECK(above.layer_seconds(i, j) == whole.layer_seconds(i + first, j + first));
  }
}

TEST_CASE(
    "layer time model: times are positive, the minimum layer time holds, thin first layers are slower") {
  std::mt19937 rng(9);
  const Mesh mesh = salient::test::random_blob(rng, 14, 20, 20);
  const ZProfile profile = profile_of(mesh);
  TimeModelParams params;
  const LayerTimeModel model(mesh, profile, params);
  for (int i = 0; i + 30 <= profile.cells(); i += 37) {
    const double t = model.layer_seconds(i, i + 30);
    CHECK(t > params.layer_overhead);
    // A layer is never quicker than the minimum layer time unless already at the slowest speed.
    const LayerFeatures f = model.features(i, i + 30);
    const double length = f.wall_length + f.solid_length + f.sparse_length;
    if (length > 0)
      CHECK(t - params.layer_overhead >=
            std::min(params.min_layer_time, length / params.min_print_speed) - 1e-9);
  }
  // A fine plan takes longer than a coarse one: more layers, same paths.
  CHECK(model.seconds(fine_plan(profile)) > model.seconds(coarse_plan(profile)));
}
