// The fixed first layer (planners/first_layer_planner): every planner keeps it and meets its
// target with it counted; a model too low to hold it above is planned whole, with a note.
#include <doctest/doctest.h>

#include <random>

#include "core/slicing/planner.hpp"
#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

TEST_CASE("first layer: each planner keeps it, E within epsilon and the count asked for include it") {
  std::mt19937 rng(21);
  const Mesh mesh = salient::test::random_blob(rng, 12, 18, 12);
  const auto saliency = salient::test::random_saliency(rng, mesh.vertex_count());
  const ZProfile profile = ZProfile::build(mesh, saliency, {});
  const Objective obj(profile, Metric::area), geo(profile, Metric::area, true);
  const LayerTimeModel time(mesh, profile);
  const double eps = obj.epsilon(0.05);
  for (int first : {10, 20, 35}) {
    CAPTURE(first);
    for (std::string_view name : planner_names()) {
      CAPTURE(name);
      const auto planner = make_planner(name);
      for (PlanGoal goal : {PlanGoal::time, PlanGoal::layers}) {
        const PlanRequest by_eps{obj, &mesh, &geo, PlanTarget::within(eps), 1, {}, goal, &time, first};
        const PlanResult r = planner->plan(by_eps);
        CHECK(check_plan(profile, r.plan) == "");
        CHECK(r.plan.width(0) == first);
        if (name != "coarse") CHECK(obj.error(r.plan) <= eps + 1e-9);
      }
      const PlanRequest by_count{obj,   &mesh, &geo, PlanTarget::count(80), 1, {}, PlanGoal::layers,
                                 &time, first};
      const PlanResult c = planner->plan(by_count);
      CHECK(c.plan.width(0) == first);
      if (name != "fine" && name != "coarse") CHECK((c.plan.layer_count() == 80 || !c.note.empty()));
    }
  }
}

TEST_CASE("first layer: a model too low to hold layers above it is planned whole, with a note") {
  const Mesh mesh = salient::test::box(5, 5, 0.25);
  const ZProfile profile = ZProfile::build(mesh, std::vector<float>(mesh.vertex_count(), 1.0f), {});
  const Objective obj(profile, Metric::area);
  const PlanRequest request{obj, &mesh, nullptr, PlanTarget::within(0), 1, {}, PlanGoal::layers, nullptr, 20};
  const PlanResult r = make_planner(PlannerKind::exact)->plan(request);
  CHECK(check_plan(profile, r.plan) == "");
  CHECK(r.note.find("first layer is not fixed") != std::string::npos);
}
