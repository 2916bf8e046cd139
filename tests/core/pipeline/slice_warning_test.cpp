// What a slice says about a model no one prints as it is: one in metres (or of unit size) read as
// millimetres, one larger than the bed, one whose open bottom would leave its layers in mid-air.
#include "core/pipeline/slice_warning.hpp"

#include <doctest/doctest.h>

#include <fstream>

#include "core/common/input_error.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/pipeline/slice_result_json.hpp"
#include "core/printer/printer_profile.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::core;

namespace {

std::string off_text(const Mesh& m) {
  std::string s =
      "OFF\n" + std::to_string(m.vertex_count()) + " " + std::to_string(m.triangle_count()) + " 0\n";
  for (const Vec3& p : m.positions)
    s += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  for (const Triangle& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

BoundingBox sized(double x, double y, double z) {
  return {{0, 0, 0}, {x, y, z}};
}

// A 20 mm box with no bottom and no lower 8 mm of one side: below 8 mm its sections are open
// U-shapes 20 mm wide, as an open-bottomed scan's are near its base.
Mesh open_bottomed_box() {
  const double corners[4][2] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}}, z[3] = {0, 8, 20};
  Mesh m;
  for (const auto& c : corners)
    for (double h : z) m.positions.push_back({c[0], c[1], h});
  const auto v = [](int corner, int level) { return static_cast<std::uint32_t>((corner % 4) * 3 + level); };
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 2; ++k) {
      if (c == 3 && k == 0) continue;  // the side's missing lower part
      m.triangles.push_back({v(c, k), v(c + 1, k), v(c + 1, k + 1)});
      m.triangles.push_back({v(c, k), v(c + 1, k + 1), v(c, k + 1)});
    }
  m.triangles.push_back({v(0, 2), v(1, 2), v(2, 2)});
  m.triangles.push_back({v(0, 2), v(2, 2), v(3, 2)});
  return m;
}

SliceResult slice_mesh(const Mesh& mesh, const std::string& name, SliceSettings settings = {}) {
  salient::test::ScratchDir dir("slice-warning");
  std::filesystem::create_directories(dir.path);
  const std::string file = (dir.path / name).string();
  std::ofstream(file) << off_text(mesh);
  settings.plan.mesh.model = file;
  settings.toolpaths.infill_density = 0.1;
  return slice_model(settings, *builtin_printer("generic-i3"), {});
}

bool has_code(const std::vector<SliceWarning>& warnings, const std::string& code) {
  for (const SliceWarning& w : warnings)
    if (w.code == code) return true;
  return false;
}

}  // namespace

TEST_CASE("a model in metres is said to be so, with its size and the fix") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  const auto w = model_size_warnings(sized(0.155, 0.12, 0.15), printer, "bunny.obj");
  REQUIRE(w.size() == 1);
  CHECK(w[0].code == "model_tiny");
  CHECK(w[0].message.find("bunny.obj is 0.15 mm tall") == 0);
  CHECK(w[0].message.find("{height}") != std::string::npos);
  CHECK(w[0].message.find("{scale} 1000") != std::string::npos);
  CHECK(spell_settings(w[0].message, [](SettingId id) {
          return "--" + std::string(setting_key(id));
        }).find("--scale 1000") != std::string::npos);
  // Of unit size: a thousand times would not fit, so only the height is offered.
  const auto unit = model_size_warnings(sized(1, 0.8, 1), printer, "unit.obj");
  REQUIRE(unit.size() == 1);
  CHECK(unit[0].message.find("{scale} 1000") == std::string::npos);
}

TEST_CASE("a model larger than the build volume is said to be so, with a scale that fits") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  const auto w = model_size_warnings(sized(400, 30, 30), printer, "part.stl");
  REQUIRE(w.size() == 1);
  CHECK(w[0].code == "model_larger_than_bed");
  CHECK(w[0].message.find("400 × 30 × 30 mm") != std::string::npos);
  CHECK(w[0].message.find("{scale} 0.45") != std::string::npos);  // 200 / 400 × 0.9
}

TEST_CASE("plausible sizes say nothing") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  CHECK(model_size_warnings(sized(40, 30, 80), printer, "bunny.obj").empty());
  CHECK(model_size_warnings(sized(100, 100, 2), printer, "plate.stl").empty());  // flat, not tiny
  CHECK(model_size_warnings(sized(200, 200, 180), printer, "full.stl").empty());
}

TEST_CASE("a model lower than the first layer is refused: nothing of it would print") {
  CHECK_THROWS_AS(check_printable_height(sized(0.15, 0.12, 0.15), 0.2, "bunny.obj"), InputError);
  CHECK_NOTHROW(check_printable_height(sized(0.3, 0.3, 0.3), 0.2, "bunny.obj"));
  try {
    slice_mesh(salient::test::box(0.15, 0.12, 0.15), "bunny.off");
    FAIL("sliced a model 0.15 mm tall");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("bunny.off: the model is 0.15 mm tall as placed") == 0);
  }
}

TEST_CASE("a slice of a tiny model carries the warning in its result and its JSON") {
  const SliceResult r = slice_mesh(salient::test::box(3, 2, 1), "unit.off");
  REQUIRE(has_code(r.warnings, "model_tiny"));
  const std::string json = slice_result_json(
      r, "generic-i3", [](SettingId id) { return "'" + std::string(setting_key(id)) + "'"; });
  CHECK(json.find("\"code\":\"model_tiny\"") != std::string::npos);
  CHECK(json.find("Give 'height' in millimetres") != std::string::npos);
  CHECK(json.find("\"saliency_method\":\"spectral saliency\"") != std::string::npos);
  CHECK_FALSE(has_code(slice_mesh(salient::test::box(30, 20, 10), "box.off").warnings, "model_tiny"));
}

TEST_CASE("an open bottom is capped in repair: the bust prints from the bed") {
  // It printed nothing from 0 to 8 mm, in mid-air above (issue 32 item 9).
  const SliceResult r = slice_mesh(open_bottomed_box(), "bust.off");
  REQUIRE_FALSE(r.z.empty());
  CHECK(r.z.front() <= 0.3);  // the first layer's top: on the bed
  CHECK(r.open_contours == 0);
}

TEST_CASE("a part floating above the rest is refused: its layers would start in mid-air, unless supported") {
  Mesh m = salient::test::box(20, 20, 2);  // on the bed
  const Mesh upper = salient::test::box(20, 20, 12);
  for (const Triangle& t : upper.triangles) m.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  for (const Vec3& v : upper.positions) m.positions.push_back({v.x, v.y, v.z + 8});
  try {
    slice_mesh(m, "floating.off");
    FAIL("sliced a model whose upper part starts 8 mm up, over nothing from 2 mm");
  } catch (const InputError& e) {
    const std::string text = e.what();
    CAPTURE(text);
    CHECK(text.find("floating.off: nothing would print from 2") == 0);
    CHECK((text.find(" to 7.9") != std::string::npos || text.find(" to 8") != std::string::npos));
    CHECK(text.find("mid-air") != std::string::npos);
    CHECK(text.find("a part floats above the rest") != std::string::npos);
    CHECK(text.find("support") != std::string::npos);
  }
  SliceSettings supported;
  supported.support = true;
  CHECK_NOTHROW(slice_mesh(m, "floating.off", supported));
}
