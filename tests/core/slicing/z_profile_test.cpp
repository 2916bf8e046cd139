// ZProfile: values on shapes whose answers are known, and the errors for impossible settings.
#include <doctest/doctest.h>

#include <numeric>

#include "core/common/input_error.hpp"
#include "core/pipeline/planning_setup.hpp"
#include "core/slicing/objective.hpp"
#include "tests/core/slicing/slicing_test_util.hpp"

using namespace salient::core;

TEST_CASE("a vertical prism has no stair steps: every plan has E = 0") {
  const Mesh box = salient::test::box(10, 10, 8);
  const std::vector<float> s(box.vertex_count(), 1.0f);
  const ZProfile p = ZProfile::build(box, s, {});
  CHECK(p.cells() == 800);
  CHECK(p.fewest_layers() == 20);
  CHECK(p.most_layers() == 80);
  for (int k = 0; k < p.cells(); ++k) CHECK(p.cos_theta()[k] == 0);  // bed and top faces add nothing
  for (Metric m : {Metric::area, Metric::paper}) {
    const Objective obj(p, m);
    CHECK(obj.e_coarse() == doctest::Approx(0));
  }
}

TEST_CASE("a pyramid's weighted areas add up to its base, and the metric grows with thickness") {
  const Mesh pyr = salient::test::pyramid(10, 5);
  const std::vector<float> s(pyr.vertex_count(), 1.0f);
  const ZProfile p = ZProfile::build(pyr, s, {});
  const auto& A = p.channel(false).A_prefix;
  CHECK(A.back() == doctest::Approx(100.0).epsilon(1e-9));  // slanted faces project onto the base
  const double cos = 5 / std::sqrt(25 + 25.0);              // |n_z| of a face of this pyramid
  CHECK(p.cos_theta()[0] == doctest::Approx(cos));
  CHECK(p.cos_theta()[p.cells() - 1] == doctest::Approx(cos));
  const Objective area(p, Metric::area), paper(p, Metric::paper);
  CHECK(area.e_coarse() > 0);
  // paper metric: SM(L) = S·h·cosθ with S = 1 and constant cosθ, so SM(plan) = H·cosθ for
  // every plan: the paper's metric cannot tell plans apart on a pyramid, ours can.
  CHECK(paper.sm(fine_plan(p)) == doctest::Approx(5 * cos));
  CHECK(paper.e_coarse() == doctest::Approx(0).epsilon(1e-9));
}

TEST_CASE("saliency weighs the area metric and bounds S") {
  Mesh pyr = salient::test::pyramid(10, 5);
  std::vector<float> s(pyr.vertex_count(), 0.0f);
  s[4] = 1.0f;  // only the apex is salient
  const ZProfile p = ZProfile::build(pyr, s, {});
  const auto& S = p.channel(false).S;
  CHECK(S.front() < 0.01f);
  CHECK(S.back() == doctest::Approx(1.0f));
  for (float v : S) CHECK((v >= 0 && v <= 1));
  // The salient field puts less weight low down than the geometric one.
  const auto& As = p.channel(false).A_prefix;
  const auto& Ag = p.channel(true).A_prefix;
  CHECK(As[100] / As.back() < Ag[100] / Ag.back());
}

TEST_CASE("impossible settings are errors naming the setting (each front end spells it)") {
  const Mesh box = salient::test::box(10, 10, 8);
  const std::vector<float> s(box.vertex_count(), 1.0f);
  CHECK_THROWS_WITH_AS(ZProfile::build(box, s, {0.5, 0.4, 0.01}),
                       "min_layer: 0.5 mm is greater than max_layer 0.4 mm", InputError);
  CHECK_THROWS_WITH_AS(ZProfile::build(box, s, {0.1, 0.4, 0.03}),
                       "grid: 0.03 mm does not divide min_layer 0.1 and max_layer 0.4", InputError);
  CHECK_THROWS_WITH_AS(ZProfile::build(box, s, {-0.1, 0.4, 0.01}),
                       "min_layer: must be a positive number of millimetres, got -0.1", InputError);
  CHECK_THROWS_WITH_AS(validate_rho(1.5), "rho: must be between 0 and 1, got 1.5", InputError);
  try {
    validate({0.1, 0.4, 0.03});
    FAIL("refused");
  } catch (const InputError& e) {
    CHECK(e.setting() == salient::core::SettingId::grid);
    const auto angled = [](salient::core::SettingId id) {  // appended: GCC 12 warns falsely on operator+
      std::string out = "<";
      return out.append(setting_key(id)).append(">");
    };
    CHECK(e.spelled(angled) == "<grid>: 0.03 mm does not divide <min_layer> 0.1 and <max_layer> 0.4");
  }
  const Mesh low = salient::test::box(10, 10, 0.05);
  CHECK_THROWS_WITH_AS(ZProfile::build(low, s, {}), "model: is 0.05 mm tall, lower than min_layer 0.1 mm",
                       InputError);
  const Mesh awkward = salient::test::box(10, 10, 0.5);
  CHECK_THROWS_WITH_AS(ZProfile::build(awkward, s, {0.3, 0.4, 0.01}),
                       "model: height 0.5 mm cannot be cut into layers of 0.3 to 0.4 mm", InputError);
}

TEST_CASE("a height off the grid ends in a thinner last cell") {
  const Mesh box = salient::test::box(10, 10, 1.005);
  const std::vector<float> s(box.vertex_count(), 1.0f);
  const ZProfile p = ZProfile::build(box, s, {});
  CHECK(p.cells() == 101);
  CHECK(p.z(p.cells()) == doctest::Approx(1.005));
  CHECK(check_plan(p, fine_plan(p)).empty());
}

TEST_CASE("the z-profile is reported and can be cancelled, as the daemon's jobs need") {
  salient::core::PlanOptions o;
  o.mesh.model = SALIENT_MODELS_DIR "/stanford-bunny.obj";  // 69,451 triangles: reported twice
  o.mesh.up = "y";
  o.mesh.height = 40;
  o.saliency = salient::core::SaliencyMethod::uniform;  // the profile's reports are the point, not saliency
  salient::core::CancelToken token;
  int profile_reports = 0;
  const salient::core::RunContext run{&token, [&](std::string_view phase, double) {
                                        if (phase != "profile") return;
                                        ++profile_reports;
                                        token.cancel();  // as a DELETE does while the profile is built
                                      }};
  CHECK_THROWS_AS(salient::core::prepare(o, run), salient::core::Cancelled);
  CHECK(profile_reports == 1);
}

TEST_CASE("faces of zero or non-finite area are left out of the profile and counted") {
  Mesh pyr = salient::test::pyramid(10, 5);
  const ZProfile clean = ZProfile::build(pyr, std::vector<float>(pyr.vertex_count(), 1.0f), {});
  CHECK(clean.dropped_faces() == 0);
  const auto a = static_cast<std::uint32_t>(pyr.positions.size());
  pyr.positions.push_back({1, 1, 1});
  pyr.positions.push_back({2, 2, 2});
  pyr.positions.push_back({3, 3, 3});  // collinear: no area
  pyr.triangles.push_back({a, a + 1, a + 2});
  const ZProfile p = ZProfile::build(pyr, std::vector<float>(pyr.vertex_count(), 1.0f), {});
  CHECK(p.dropped_faces() == 1);
  CHECK(p.channel(false).A_prefix.back() == doctest::Approx(clean.channel(false).A_prefix.back()));
}
