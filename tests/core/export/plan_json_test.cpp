// The plan format (docs/plan-format.md): what plan_json writes, read_plan_json reads back; old
// `salient plan -o` files are still read; newer versions and other shapes are refused by name.
#include "core/export/plan_json.hpp"

#include <doctest/doctest.h>

#include "core/common/input_error.hpp"

using namespace salient::core;

namespace {

PlanDocument two_layers() {
  PlanDocument d;
  d.model = "cube.ply";
  d.planner = "exact";
  d.metric = "area";
  d.height = 0.5;
  d.grid = 0.01, d.min_layer = 0.1, d.max_layer = 0.4;
  d.fine_layers = 5, d.coarse_layers = 2;
  d.error = 0.25, d.rsmd = 0.5;
  d.epsilon = 0.3, d.rho = 0.05;
  d.layers = {{0, 0.2, 0.2, 0.5, 1.0, 0.1}, {0.2, 0.5, 0.3, 0.25, 0.0, 0.15}};
  return d;
}

std::string refusal(const std::string& text) {
  try {
    read_plan_json(text, "p.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a plan written is read back: its layers, boundaries and summary") {
  const std::string text = plan_json(two_layers());
  CHECK(text.find("\"format\": \"salient-plan\"") != std::string::npos);
  CHECK(text.find("\"version\": 1") != std::string::npos);
  CHECK(text.find("\"segmentation\": null") != std::string::npos);
  CHECK(text.back() == '\n');
  const PlanDocument back = read_plan_json(text, "p.json");
  CHECK(back.model == "cube.ply");
  CHECK(back.planner == "exact");
  CHECK(back.count() == 2);
  CHECK(back.boundaries() == std::vector<double>{0, 0.2, 0.5});
  CHECK(back.layers[1].height == doctest::Approx(0.3));
  CHECK(*back.layers[0].saliency == 0.5);
  CHECK(back.height == 0.5);
  CHECK(*back.epsilon == 0.3);
  CHECK_FALSE(back.requested_layers);
  CHECK(plan_json(back) == text);  // nothing lost on the way (but the SegOpt report)
}

TEST_CASE("a plan's objective and minutes against the uniform baselines are written and read back") {
  PlanDocument d = two_layers();
  d.objective = "time";
  PlanTimes t;
  t.plan_seconds = 3000;
  t.fine_layers = 400;
  t.fine_seconds = 4000;
  t.default_layer_height = 0.2;
  t.default_layers = 200;
  t.default_seconds = 2500;
  t.default_rsmd = 0.33;
  d.times = t;
  const std::string text = plan_json(d);
  CHECK(text.find("\"saving_vs_fine_percent\": 25.0") != std::string::npos);
  CHECK(text.find("\"saving_vs_default_s\": -500.0") != std::string::npos);
  const PlanDocument back = read_plan_json(text, "p.json");
  CHECK(back.objective == "time");
  REQUIRE(back.times);
  CHECK(back.times->fine_layers == 400);
  CHECK(back.times->default_rsmd == 0.33);
  CHECK(back.times->saving_vs_fine() == 1000);
  CHECK(plan_json(back) == text);
  // A plan without them (older salient) has none.
  CHECK_FALSE(read_plan_json(plan_json(two_layers()), "p.json").times);
}

TEST_CASE("a segmented plan: printed layers without the objective's view, and the SegOpt report") {
  PlanDocument d = two_layers();
  for (PlanLayer& l : d.layers) l.saliency.reset(), l.cos.reset(), l.sm.reset();
  SegmentationReport s;
  s.cut = true;
  s.note = "cut: 2 regions";
  s.regions.resize(2);
  s.regions[0].side = 0, s.regions[1].side = 1;
  s.regions[0].boundaries = {0, 0.2, 0.5};
  s.regions[1].clip = {{0, 0}, {1, 0}, {1, 1}};
  s.plane = SegmentationReport::Plane{};
  d.segmentation = s;
  const std::string text = plan_json(d);
  CHECK(text.find("\"saliency\"") == std::string::npos);
  CHECK(text.find("\"regions\"") != std::string::npos);
  CHECK(read_plan_json(text, "p.json").boundaries() == std::vector<double>{0, 0.2, 0.5});
  const std::string report = segmentation_json(s);
  CHECK(report.find("\"boundaries\":[0.0,0.2,0.5]") != std::string::npos);
  CHECK(report.find("\"plane\":{") != std::string::npos);
  CHECK(text.find("\"clip\": [") != std::string::npos);
}

TEST_CASE("a plan from before version 1 (`salient plan -o`, no format) is read") {
  const PlanDocument old = read_plan_json(
      R"({"planner": "exact", "count": 2, "height": 0.5,
          "layers": [{"z_bottom": 0, "z_top": 0.2, "height": 0.2, "saliency": 1, "cos": 1, "sm": 0},
                     {"z_bottom": 0.2, "z_top": 0.5, "height": 0.3, "saliency": 1, "cos": 1, "sm": 0}]})",
      "old.json");
  CHECK(old.boundaries() == std::vector<double>{0, 0.2, 0.5});
  CHECK(old.planner == "exact");
}

TEST_CASE("the reader refuses what it cannot read, naming the field or the version") {
  CHECK(refusal("{not json").find("p.json: byte") == 0);
  CHECK(refusal("[1, 2]") == "p.json: is not a plan (a JSON object with \"format\": \"salient-plan\")");
  CHECK(refusal(R"({"format": "gcode", "version": 1, "layers": []})") ==
        "p.json: is not a plan: field 'format' is \"gcode\", not \"salient-plan\"");
  CHECK(refusal(R"({"format": "salient-plan", "version": 2, "layers": [{"z_top": 1}]})") ==
        "p.json: is a salient-plan of version 2; this salient reads up to version 1");
  CHECK(refusal(R"({"format": "salient-plan", "layers": [{"z_top": 1}]})") ==
        "p.json: field 'version' is missing or not a version number");
  // The older daemon's /plan and `plan --segment -o`: no format, no array of layers.
  CHECK(refusal(R"({"model": "a.stl", "z": [0.2, 0.4], "layers": 2})").find("has no field 'format'") !=
        std::string::npos);
  CHECK(refusal(R"({"printed_heights": [0.2, 0.4]})").find("has no field 'format'") != std::string::npos);
  CHECK(refusal(R"({"format": "salient-plan", "version": 1, "layers": []})") ==
        "p.json: field 'layers' is missing or empty (write plans with `salient plan -o`)");
  CHECK(refusal(R"({"format": "salient-plan", "version": 1, "layers": [{"z_top": "high"}]})") ==
        "p.json: field 'layers[0].z_top' is missing or not a number");
  CHECK(refusal(R"({"format": "salient-plan", "version": 1, "layers": [{"z_top": 0.3}, {"z_top": 0.2}]})") ==
        "p.json: field 'layers[1].z_top' does not rise");
  CHECK(refusal(R"({"format": "salient-plan", "version": 1, "count": 3, "layers": [{"z_top": 0.3}]})") ==
        "p.json: field 'count' is 3 but 'layers' has 1");
}
