// Properties every planner must have, on every shared model and both metrics: valid plans
// (α..ᾱ, summing to H), E ≤ ε when asked for ε, the requested count when reachable, and never
// better than `exact` (fewer layers at equal ε, lower E at equal count). adapslice's trace
// never gains layers. With a fixed first layer (the printer's) the same hold above it.
#include <doctest/doctest.h>

#include <filesystem>

#include "core/common/input_error.hpp"
#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/placement.hpp"
#include "core/slicing/planner.hpp"
#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

namespace {

void check_all_planners(const Mesh& mesh, const std::vector<float>& saliency, Metric metric,
                        int first_cells = 0) {
  CAPTURE(first_cells);
  const ZProfile profile = ZProfile::build(mesh, saliency, {});
  const Objective obj(profile, metric), geo(profile, metric, true);
  const double eps = obj.epsilon(0.05);
  const double slack = 1e-9 * std::max(1.0, obj.e_coarse());
  const auto request = [&](PlanTarget t) {
    return PlanRequest{obj, &mesh, &geo, t, 3, {}, PlanGoal::layers, nullptr, first_cells};
  };
  const PlanResult exact_eps = make_planner("exact")->plan(request(PlanTarget::within(eps)));
  const int n_ref = exact_eps.plan.layer_count();
  const PlanResult exact_n = make_planner("exact")->plan(request(PlanTarget::count(n_ref)));
  for (std::string_view name : planner_names()) {
    CAPTURE(name);
    const PlannerKind kind = *parse_planner(name);
    const auto planner = make_planner(kind);
    REQUIRE(planner);
    const PlanResult by_eps = planner->plan(request(PlanTarget::within(eps)));
    const PlanResult by_count = planner->plan(request(PlanTarget::count(n_ref)));
    for (const PlanResult* r : {&by_eps, &by_count}) {
      CHECK(check_plan(profile, r->plan) == "");
      CHECK(profile.z(r->plan.boundaries.back()) == doctest::Approx(profile.height()));
      if (first_cells > 0) CHECK(r->plan.width(0) == first_cells);
    }
    if (kind != PlannerKind::coarse) {  // coarse ignores ε by definition
      CHECK(obj.error(by_eps.plan) <= eps + slack);
      CHECK(by_eps.plan.layer_count() >= n_ref);  // never fewer layers than exact within ε
    }
    if (by_count.plan.layer_count() == n_ref)
      CHECK(obj.error(by_count.plan) >= obj.error(exact_n.plan) - slack);  // never lower E than exact
    // The requested count, or the nearest the planner's parameter reaches, with a note saying so.
    if (kind != PlannerKind::fine && kind != PlannerKind::coarse)
      CHECK((by_count.plan.layer_count() == n_ref || !by_count.note.empty()));
    for (std::size_t i = 1; i < by_eps.trace.size(); ++i)
      CHECK(by_eps.trace[i].layers <= by_eps.trace[i - 1].layers);
  }
}

void check_model(const char* file, const char* up) {
  CAPTURE(file);
  LoadedMesh m = load_mesh(std::filesystem::path(salient::test::model_path(file)));
  PlacementOptions o;
  o.up = *parse_up_axis(up);
  o.target_height = 80;
  place_mesh(m.mesh, o);
  std::mt19937 rng(11);
  const auto uniform = std::vector<float>(m.mesh.vertex_count(), 1.0f);
  const auto painted = salient::test::random_saliency(rng, m.mesh.vertex_count());
  for (Metric metric : {Metric::area, Metric::paper}) {
    CAPTURE(metric_name(metric));
    check_all_planners(m.mesh, uniform, metric);
    check_all_planners(m.mesh, painted, metric);
  }
  check_all_planners(m.mesh, painted, Metric::area, 20);  // a 0.2 mm first layer
}

}  // namespace

TEST_CASE("planner properties: stanford-bunny") {
  check_model("stanford-bunny.obj", "y");
}
TEST_CASE("planner properties: spot, cow") {
  check_model("spot.obj", "y");
  check_model("cow.obj", "y");
}
TEST_CASE("planner properties: fandisk, teapot, suzanne") {
  check_model("fandisk.obj", "y");
  check_model("teapot.obj", "y");
  check_model("suzanne.obj", "y");
}
TEST_CASE("planner properties: alligator, beetle, woody") {
  check_model("alligator.obj", "y");
  check_model("beetle.obj", "y");
  check_model("woody.obj", "y");
}
TEST_CASE("planner properties: igea") {
  check_model("igea.ply", "z");
}
TEST_CASE("planner properties: STL and PLY edge cases") {
  check_model("Spider_binary.stl", "z");
  check_model("sphereWithHole.stl", "z");
  check_model("cube_binary.ply", "z");
}

TEST_CASE("a flat model cannot be planned, with a clear error") {
  LoadedMesh m = load_mesh(std::filesystem::path(salient::test::model_path("triangle_with_two_solids.stl")));
  place_mesh(m.mesh, {});
  const std::vector<float> s(m.mesh.vertex_count(), 1.0f);
  CHECK_THROWS_WITH_AS(ZProfile::build(m.mesh, s, {}), "model: is 0 mm tall, lower than min_layer 0.1 mm",
                       InputError);
}
