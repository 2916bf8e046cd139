// A plan from elsewhere on our grid: our own planners' plans, written as tops in mm and read back,
// score exactly as they did; compare_with_plan never finds exact worse than the given plan at its
// count; tops that do not fit the model are refused naming the line.
#include "core/slicing/given_plan.hpp"

#include <doctest/doctest.h>

#include <functional>
#include <random>

#include "core/common/input_error.hpp"
#include "core/slicing/comparison.hpp"
#include "core/slicing/objective.hpp"
#include "core/slicing/planner.hpp"
#include "core/slicing/z_profile.hpp"
#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

namespace {

std::vector<double> tops_of(const ZProfile& p, const LayerPlan& plan) {
  std::vector<double> z;
  for (std::size_t i = 1; i < plan.boundaries.size(); ++i) z.push_back(p.z(plan.boundaries[i]));
  return z;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE(
    "given plans: any plan written as tops reads back as itself and scores the same, and exact is never "
    "worse") {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    const Mesh m = salient::test::random_blob(rng, 12, 16, 8 + trial);
    const std::vector<float> s = salient::test::random_saliency(rng, m.vertex_count());
    const ZProfile p = ZProfile::build(m, s, {});
    const Objective obj(p, Metric::area);
    const Objective geometric(p, Metric::area, true);
    const PlanRequest base{obj, &m, &geometric, PlanTarget::within(0), 1, {}};
    for (const char* name : {"exact", "cusp", "random", "uniform"}) {
      const int n = p.fewest_layers() + static_cast<int>(rng() % (p.most_layers() - p.fewest_layers() + 1));
      const LayerPlan plan =
          make_planner(name)->plan(PlanRequest{obj, &m, &geometric, PlanTarget::count(n), 1, {}}).plan;
      // Jitter each top by less than half a cell: a slicer's rounding.
      std::vector<double> tops = tops_of(p, plan);
      std::uniform_real_distribution<double> jitter(-0.004, 0.004);
      for (std::size_t i = 0; i + 1 < tops.size(); ++i) tops[i] += jitter(rng);
      const GivenPlan g = given_plan(p, tops, {}, "t");
      CHECK(g.plan == plan);
      CHECK(g.outside_limits == 0);
      const std::string_view planners[] = {"exact", "hms", "uniform"};
      const Comparison c = compare_with_plan(base, g.plan, "given", planners);
      REQUIRE(c.rows.size() == 4);
      CHECK(c.rows[0].rsmd_at_count == doctest::Approx(obj.rsmd(plan)));
      CHECK(c.rows[1].layers_at_count == plan.layer_count());
      CHECK(c.rows[1].rsmd_at_count <= c.rows[0].rsmd_at_count + 1e-9);  // exact is the optimum
      CHECK(c.rows[1].layers_at_rsmd <= plan.layer_count());
    }
  }
}

TEST_CASE("given plans: a last layer a little short of or past the top ends at the top") {
  const Mesh box = salient::test::box(10, 10, 8);
  const ZProfile p = ZProfile::build(box, std::vector<float>(box.vertex_count(), 1.0f), {});
  std::vector<double> tops;
  for (int i = 1; i <= 39; ++i) tops.push_back(0.2 * i);
  for (double last : {7.85, 8.0, 8.15}) {
    std::vector<double> t = tops;
    t.push_back(last);
    const GivenPlan g = given_plan(p, t, {}, "t");
    CHECK(g.plan.layer_count() == 40);
    CHECK(g.plan.boundaries.back() == p.cells());
    CHECK(g.top == last);
  }
  // Layers past the top before the last one are above the model: dropped.
  std::vector<double> t = tops;
  t.insert(t.end(), {8.0, 8.2});
  CHECK(given_plan(p, t, {}, "t").plan.layer_count() == 40);
  // A first layer of 0.05 mm counts as outside the limits, and is scored all the same.
  std::vector<double> thin{0.05};
  for (int i = 1; i <= 40; ++i) thin.push_back(0.2 * i);
  CHECK(given_plan(p, thin, {}, "t").outside_limits == 1);
}

TEST_CASE("given plans: tops that do not fit the model are refused naming the line") {
  const Mesh box = salient::test::box(10, 10, 8);
  const ZProfile p = ZProfile::build(box, std::vector<float>(box.vertex_count(), 1.0f), {});
  std::vector<double> tops;
  std::vector<std::uint64_t> lines;
  for (int i = 1; i <= 30; ++i) tops.push_back(0.2 * i), lines.push_back(10 * i);
  CHECK(error_of([&] { given_plan(p, tops, lines, "short.gcode"); }) ==
        "short.gcode:300: layers end at 6.000 mm, the model is 8.000 mm tall: the plan does not cover it "
        "(another "
        "model, size or placement?)");
  std::vector<double> tall = tops;
  for (int i = 31; i <= 60; ++i) tall.push_back(0.2 * i), lines.push_back(10 * i);
  CHECK(error_of([&] {
          given_plan(p, tall, lines, "tall.gcode");
        }).starts_with("tall.gcode:430: layer top 8.600 mm is above"));
  CHECK(error_of([&] {
          given_plan(p, {0.2, 0.203, 8.0}, {1, 2, 3}, "fine.gcode");
        }).starts_with("fine.gcode:2: layer top 0.203 mm lies in the same 0.010 mm grid cell"));
  CHECK(error_of([&] { given_plan(p, {}, {}, "none.gcode"); }) == "none.gcode: has no layers");
}
