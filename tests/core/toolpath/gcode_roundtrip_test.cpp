// Toolpaths and G-code, re-parsed: every layer at the plan's Z and height, every move on the bed,
// the extruded volume of each layer within 10 % of the walls + infill it should fill, and E
// consistent with relative or absolute mode. Runs on a variable-height plan.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "core/common/input_error.hpp"
#include "core/gcode/gcode_line.hpp"
#include "core/gcode/gcode_writer.hpp"
#include "core/gcode/time_estimator.hpp"
#include "core/mesh/placement.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/toolpath/support_generator.hpp"
#include "core/toolpath/toolpath_generator.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

struct ParsedLayer {
  double z = 0, height = 0, e = 0;
  double move_z = -1;  // the Z the nozzle moved to in this layer
};

struct Parsed {
  std::vector<ParsedLayer> layers;
  double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
  double e_total = 0;
  bool monotonic_absolute_e = true;
  std::size_t arcs = 0;
};

Parsed parse(const std::string& text, bool relative) {
  Parsed p;
  std::istringstream in(text);
  std::string line;
  double e_abs = 0, last_e = 0;
  bool in_body = false;
  while (std::getline(in, line)) {
    if (line.rfind("M73 P100", 0) == 0) break;  // the end G-code (park, motors off) follows
    if (line.rfind(";LAYER_CHANGE", 0) == 0) {
      p.layers.emplace_back();
      in_body = true;
      continue;
    }
    if (line.rfind(";Z:", 0) == 0) p.layers.back().z = std::stod(line.substr(3));
    if (line.rfind(";HEIGHT:", 0) == 0) p.layers.back().height = std::stod(line.substr(8));
    GcodeError err;
    const GcodeLine g = parse_gcode_line(line, err);
    REQUIRE(err == GcodeError::none);
    if (!in_body || !(g.is('G', 0) || g.is('G', 1) || g.is('G', 2) || g.is('G', 3))) continue;
    if (g.is('G', 2) || g.is('G', 3)) ++p.arcs;
    if (g.has('Z')) p.layers.back().move_z = g.get('Z');
    if (g.has('X')) p.min_x = std::min(p.min_x, g.get('X')), p.max_x = std::max(p.max_x, g.get('X'));
    if (g.has('Y')) p.min_y = std::min(p.min_y, g.get('Y')), p.max_y = std::max(p.max_y, g.get('Y'));
    if (g.has('E')) {
      const double de = relative ? g.get('E') : g.get('E') - last_e;
      if (!relative) last_e = g.get('E');
      if (g.has('X') || g.has('Y')) {
        p.layers.back().e += de;
        if (de < 0) p.monotonic_absolute_e = false;
      }
      e_abs += de;
    }
  }
  p.e_total = e_abs;
  return p;
}

// A box standing at the centre of the printer's bed.
Mesh box_on_bed(const PrinterProfile& printer, double sx, double sy, double sz) {
  Mesh box = salient::test::box(sx, sy, sz);
  PlacementOptions o;
  o.bed_center_x = printer.bed_center_x();
  o.bed_center_y = printer.bed_center_y();
  place_mesh(box, o);
  return box;
}

// Layers of 0.1 … 0.3 mm up to 6 mm.
std::vector<double> variable_plan() {
  std::vector<double> z{0};
  const double steps[] = {0.2, 0.1, 0.3, 0.25, 0.15};
  for (int i = 0; z.back() < 6 - 1e-9; ++i) z.push_back(std::min(6.0, z.back() + steps[i % 5]));
  return z;
}

}  // namespace

TEST_CASE("G-code follows the plan and extrudes what the layers need") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  const Mesh box = box_on_bed(printer, 20, 20, 6);
  const std::vector<double> z = variable_plan();
  ToolpathSettings s;
  const auto layers = generate_toolpaths(box, z, s);
  REQUIRE(layers.size() == z.size() - 1);
  for (bool relative : {true, false}) {
    CAPTURE(relative);
    GcodeSettings gs;
    gs.relative_e = relative;
    const GcodeResult g = write_gcode(layers, printer, gs);
    const Parsed p = parse(g.text, relative);
    REQUIRE(p.layers.size() == layers.size());
    const double filament_area = M_PI * printer.filament_diameter * printer.filament_diameter / 4;
    for (std::size_t i = 0; i < layers.size(); ++i) {
      CAPTURE(i);
      CHECK(p.layers[i].z == doctest::Approx(z[i + 1]).epsilon(1e-6));
      CHECK(p.layers[i].move_z == doctest::Approx(z[i + 1]).epsilon(1e-6));
      CHECK(p.layers[i].height == doctest::Approx(z[i + 1] - z[i]).epsilon(1e-3));
      if (i == 0) continue;  // the skirt is extra on the first layer
      const LayerToolpaths& l = layers[i];
      const double expected = (l.wall_area + l.solid_area + s.infill_density * l.sparse_area) * l.height();
      const double extruded = p.layers[i].e * filament_area;
      CHECK(extruded == doctest::Approx(expected).epsilon(0.10));
    }
    // Solid skins: the bottom 0.8 mm and top 0.8 mm are solid, the middle is sparse.
    CHECK(layers[1].sparse_area == doctest::Approx(0).epsilon(1e-9));
    CHECK(layers[layers.size() / 2].sparse_area > 0);
    CHECK(layers.back().sparse_area == doctest::Approx(0).epsilon(1e-9));
    // On the bed, and around the box's footprint (centre 100,100; skirt 3 mm out).
    CHECK(p.min_x >= 0);
    CHECK(p.max_x <= printer.bed_width);
    CHECK(p.min_y >= 0);
    CHECK(p.max_y <= printer.bed_depth);
    CHECK(p.min_x == doctest::Approx(100 - 10 - 3 - s.line_width / 2).epsilon(0.01));
    CHECK(p.e_total <= g.filament_mm + 1e-3);  // the body's; the header's adds the start code's prime line
    if (!relative) CHECK(p.monotonic_absolute_e);
    CHECK(g.seconds > 0);
  }
}

TEST_CASE(
    "the header's layers and filament are the file's: the start code is no layer, its prime line is "
    "filament") {
  for (const char* id : {"generic-i3", "ender3", "replicator2x"}) {
    CAPTURE(id);
    const PrinterProfile printer = *builtin_printer(id);
    const auto layers = generate_toolpaths(box_on_bed(printer, 20, 20, 6), variable_plan(), {});
    const GcodeResult g = write_gcode(layers, printer, {});
    const GcodeEstimate read = estimate_gcode(g.text, id);
    CHECK(read.layer_seconds.size() == layers.size());
    CHECK(read.filament_mm == doctest::Approx(g.filament_mm).epsilon(1e-4));
  }
}

TEST_CASE("a model too big for the bed, or too tall, is refused") {
  const PrinterProfile printer = *builtin_printer("replicator2x");
  Mesh big = salient::test::box(300, 20, 5);
  place_mesh(big, {});
  const auto layers = generate_toolpaths(big, {0, 0.2, 0.4}, {});
  CHECK_THROWS_AS(write_gcode(layers, printer, {}), InputError);
  Mesh tall = salient::test::box(10, 10, 200);
  place_mesh(tall, {});
  const auto tall_layers = generate_toolpaths(tall, {0, 100, 200}, {});
  CHECK_THROWS_WITH_AS(write_gcode(tall_layers, printer, {}),
                       "model: is 200.0 mm tall, the MakerBot Replicator 2X prints up to 150.0 mm",
                       InputError);
}

TEST_CASE("flow: the cross-section of a line") {
  CHECK(extrusion_area(0.45, 0.2) == doctest::Approx(0.25 * 0.2 + M_PI * 0.01));
  CHECK(extrusion_area(0.4, 0.4) == doctest::Approx(M_PI * 0.04));
}

TEST_CASE("infill combined over thin layers: fewer passes, the same material") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  const Mesh box = box_on_bed(printer, 20, 20, 6);
  std::vector<double> z;
  for (int i = 0; i <= 60; ++i) z.push_back(i * 0.1);  // 0.1 mm layers
  ToolpathSettings every, combined;
  combined.combine_infill_up_to = 0.4;
  const auto a = generate_toolpaths(box, z, every);
  const auto b = generate_toolpaths(box, z, combined);
  const auto sparse_passes = [](const std::vector<LayerToolpaths>& layers) {
    std::size_t n = 0;
    for (const auto& l : layers)
      for (const auto& p : l.paths) n += p.role == ExtrusionRole::sparse_infill;
    return n;
  };
  CHECK(sparse_passes(b) < sparse_passes(a) / 2);
  bool thick = false;
  for (const auto& l : b)
    for (const auto& p : l.paths)
      if (p.role == ExtrusionRole::sparse_infill && p.height > 0) {
        CHECK(p.height <= 0.4 + 1e-9);
        thick = true;
      }
  CHECK(thick);
  const double ga = write_gcode(a, printer, {}).filament_mm, gb = write_gcode(b, printer, {}).filament_mm;
  CHECK(gb == doctest::Approx(ga).epsilon(0.05));
}

TEST_CASE("combing: travels inside the part do not retract, travels across the outline do") {
  PrinterProfile printer = *builtin_printer("generic-i3");
  LayerToolpaths layer;
  layer.z_bottom = 0;
  layer.z_top = 0.2;
  layer.region = {{{50, 50}, {150, 50}, {150, 150}, {50, 150}}};
  layer.paths.push_back({{{60, 60}, {70, 60}}, false, 0.45, ExtrusionRole::solid_infill});
  layer.paths.push_back(
      {{{140, 140}, {130, 140}}, false, 0.45, ExtrusionRole::solid_infill});  // far, but inside
  LayerToolpaths ring = layer;
  ring.region = {{{50, 50}, {150, 50}, {150, 150}, {50, 150}},
                 {{80, 80}, {80, 120}, {120, 120}, {120, 80}}};  // a hole
  const auto retractions = [&](const LayerToolpaths& l) {
    GcodeSettings s;
    const std::string text = write_gcode({l}, printer, s).text;
    std::size_t n = 0;
    for (std::size_t at = text.find("G1 E-"); at != std::string::npos; at = text.find("G1 E-", at + 1)) ++n;
    return n;
  };
  CHECK(retractions(layer) == 1);  // only before the first move
  CHECK(retractions(ring) == 2);   // the diagonal travel crosses the hole
}

TEST_CASE("support goes under overhangs and nowhere else") {
  // A 10 × 10 × 10 pillar carrying a 30 × 10 × 2 plate that overhangs it by 10 mm each side.
  Mesh t = salient::test::box(10, 10, 10);
  Mesh plate = salient::test::box(30, 10, 2);
  for (Vec3& p : plate.positions) p += Vec3{-10, 0, 10};
  for (Triangle tri : plate.triangles) {
    for (std::uint32_t& v : tri) v += 8;
    t.triangles.push_back(tri);
  }
  t.positions.insert(t.positions.end(), plate.positions.begin(), plate.positions.end());
  std::vector<double> z;
  for (int i = 0; i <= 60; ++i) z.push_back(i * 0.2);
  auto layers = generate_toolpaths(t, z, {});
  add_support(layers, {});
  double min_x = 1e9, max_x = -1e9;
  std::size_t supported_layers = 0;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    bool any = false;
    for (const auto& p : layers[i].paths) {
      if (p.role != ExtrusionRole::support) continue;
      any = true;
      for (const Point2& q : p.points) {
        min_x = std::min(min_x, q.x), max_x = std::max(max_x, q.x);
        CHECK_FALSE((q.x > -0.5 && q.x < 10.5));  // never inside the pillar (plus its gap)
      }
    }
    if (any) {
      ++supported_layers;
      CHECK(layers[i].z_top < 10 - 0.2 + 1e-9);  // one layer's gap under the plate, none above
    }
  }
  CHECK(supported_layers == 49);  // z 0.2 … 9.8
  CHECK(min_x < -8);
  CHECK(max_x > 18);
  auto plain = generate_toolpaths(salient::test::box(10, 10, 10), z, {});
  add_support(plain, {});
  for (const auto& l : plain)
    for (const auto& p : l.paths) CHECK(p.role != ExtrusionRole::support);
}

TEST_CASE("a two-region plan prints each half at its own heights, merged by print height") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  const Mesh box = box_on_bed(printer, 20, 10, 6);  // x from 90 to 110
  std::vector<double> fine, coarse;
  for (int i = 0; i <= 60; ++i) fine.push_back(i * 0.1);
  for (int i = 0; i <= 20; ++i) coarse.push_back(i * 0.3);
  ToolpathSettings left, right;
  left.clip = {{{0, 0}, {100, 0}, {100, 200}, {0, 200}}};
  right.clip = {{{100, 0}, {200, 0}, {200, 200}, {100, 200}}};
  left.skirt_distance = right.skirt_distance = 0;
  const auto merged =
      merge_by_print_height({generate_toolpaths(box, fine, left), generate_toolpaths(box, coarse, right)});
  CHECK(merged.size() == 60);  // every 0.3 mm top is also a 0.1 mm top
  double expected = 0;
  std::size_t thick_paths = 0;
  for (const auto& l : merged)
    for (const auto& p : l.paths) {
      CHECK((std::fabs(p.height - 0.1) < 1e-9 || std::fabs(p.height - 0.3) < 1e-9));
      thick_paths += p.height > 0.2;
      for (const Point2& q : p.points)
        CHECK(((p.height < 0.2) == (q.x < 100 + 1e-6)));  // each half its own height
    }
  CHECK(thick_paths > 0);
  const auto fine_layers = generate_toolpaths(box, fine, left),
             coarse_layers = generate_toolpaths(box, coarse, right);
  for (const auto* set : {&fine_layers, &coarse_layers})
    for (const auto& l : *set) expected += (l.wall_area + l.solid_area + 0.2 * l.sparse_area) * l.height();
  const GcodeResult g = write_gcode(merged, printer, {});
  const double extruded = g.filament_mm * M_PI * printer.filament_diameter * printer.filament_diameter / 4;
  CHECK(extruded == doctest::Approx(expected).epsilon(0.10));
  const Parsed parsed = parse(g.text, true);
  REQUIRE(parsed.layers.size() == 60);
  for (std::size_t i = 0; i < 60; ++i)
    CHECK(parsed.layers[i].z == doctest::Approx(fine[i + 1]).epsilon(1e-6));
}

TEST_CASE("flavours: Marlin states its limits, Sailfish takes absolute E and MakerBot fan codes") {
  Mesh box = salient::test::box(10, 10, 2);
  PlacementOptions o;
  place_mesh(box, o);  // centred on (0, 0): the Replicator's origin is the bed centre
  const auto layers = generate_toolpaths(box, {0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0}, {});
  const std::string sailfish = write_gcode(layers, *builtin_printer("replicator2x"), {}).text;
  CHECK(sailfish.find("M82") != std::string::npos);
  CHECK(sailfish.find("M83") == std::string::npos);
  CHECK(sailfish.find("M126 T0") != std::string::npos);
  CHECK(sailfish.find("M106") == std::string::npos);
  CHECK(sailfish.find("M204") == std::string::npos);
  CHECK(sailfish.find("M136") != std::string::npos);  // the profile's start G-code
  const Mesh placed = box_on_bed(*builtin_printer("generic-i3"), 10, 10, 2);
  const auto marlin_layers =
      generate_toolpaths(placed, {0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0}, {});
  const std::string marlin = write_gcode(marlin_layers, *builtin_printer("generic-i3"), {}).text;
  CHECK(marlin.find("M204 P1000") != std::string::npos);
  CHECK(marlin.find("M106 S255") != std::string::npos);
  CHECK(marlin.find("M83") != std::string::npos);
  CHECK(marlin.find("M190 S60") != std::string::npos);  // template filled from the profile
  CHECK(marlin.find("{bed_temperature}") == std::string::npos);
}

TEST_CASE("a speck of a layer is slowed for cooling, but never below the minimum print speed") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  std::vector<LayerToolpaths> layers(2);
  for (std::size_t i = 0; i < layers.size(); ++i) {
    layers[i].z_bottom = 0.2 * static_cast<double>(i), layers[i].z_top = 0.2 * static_cast<double>(i + 1);
    ExtrusionPath speck;  // 0.05 mm of extrusion: 0.001 s at full speed
    speck.points = {{100, 100}, {100.05, 100}};
    layers[i].paths.push_back(speck);
  }
  const GcodeResult g = write_gcode(layers, printer, {});
  CHECK(std::isfinite(g.seconds));
  std::istringstream in(g.text);
  int extrusions = 0;
  double feed = 0;  // modal: F stands until the next one
  for (std::string line; std::getline(in, line);) {
    if (const std::size_t f = line.find(" F"); line[0] == 'G' && f != std::string::npos)
      feed = std::stod(line.substr(f + 2));
    if (line.rfind("G1 X", 0) != 0 || line.find(" E") == std::string::npos) continue;
    CHECK(feed >= 10.0 * 60 - 1e-9);  // mm/min
    ++extrusions;
  }
  CHECK(extrusions == 2);
}

TEST_CASE("arc fitting: G2/G3 for Marlin, fewer lines, the same layers and material, never for Sailfish") {
  PrinterProfile printer = *builtin_printer("generic-i3");
  // A cylinder (r 8 mm, 6 mm tall, 256 facets) with a 3 mm hole: its walls are arcs.
  Mesh tube = salient::test::box(1, 1, 1);
  tube.positions.clear(), tube.triangles.clear();
  const int n = 256;
  for (double r : {8.0, 1.5})
    for (double z : {0.0, 6.0})
      for (int k = 0; k < n; ++k)
        tube.positions.push_back({r * std::cos(2 * M_PI * k / n), r * std::sin(2 * M_PI * k / n), z});
  const auto v = [&](int ring, int level, int k) {
    return std::uint32_t(ring * 2 * n + level * n + (k % n));
  };
  for (int k = 0; k < n; ++k) {
    // outer wall (outward), inner wall (inward), top and bottom annuli
    tube.triangles.push_back({v(0, 0, k), v(0, 0, k + 1), v(0, 1, k + 1)});
    tube.triangles.push_back({v(0, 0, k), v(0, 1, k + 1), v(0, 1, k)});
    tube.triangles.push_back({v(1, 0, k), v(1, 1, k + 1), v(1, 0, k + 1)});
    tube.triangles.push_back({v(1, 0, k), v(1, 1, k), v(1, 1, k + 1)});
    tube.triangles.push_back({v(0, 1, k), v(0, 1, k + 1), v(1, 1, k + 1)});
    tube.triangles.push_back({v(0, 1, k), v(1, 1, k + 1), v(1, 1, k)});
    tube.triangles.push_back({v(0, 0, k), v(1, 0, k + 1), v(0, 0, k + 1)});
    tube.triangles.push_back({v(0, 0, k), v(1, 0, k), v(1, 0, k + 1)});
  }
  PlacementOptions o;
  o.bed_center_x = printer.bed_center_x(), o.bed_center_y = printer.bed_center_y();
  place_mesh(tube, o);
  const std::vector<double> z = variable_plan();
  const auto layers = generate_toolpaths(tube, z, {});
  const GcodeResult lines = write_gcode(layers, printer, {});
  printer.arc_fitting = true;
  const GcodeResult arcs = write_gcode(layers, printer, {});
  const auto count_lines = [](const std::string& t) { return std::count(t.begin(), t.end(), '\n'); };
  CHECK(count_lines(arcs.text) < count_lines(lines.text) * 3 / 4);
  const Parsed p = parse(arcs.text, true), q = parse(lines.text, true);
  CHECK(p.arcs > 0);
  CHECK(q.arcs == 0);
  REQUIRE(p.layers.size() == layers.size());
  const double filament_area = M_PI * printer.filament_diameter * printer.filament_diameter / 4;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    CAPTURE(i);
    CHECK(p.layers[i].z == doctest::Approx(z[i + 1]).epsilon(1e-6));
    CHECK(p.layers[i].move_z == doctest::Approx(z[i + 1]).epsilon(1e-6));
    CHECK(p.layers[i].e == doctest::Approx(q.layers[i].e).epsilon(0.01));  // an arc's E is for its length
    if (i == 0) continue;
    const LayerToolpaths& l = layers[i];
    const double expected = (l.wall_area + l.solid_area + 0.2 * l.sparse_area) * l.height();
    CHECK(p.layers[i].e * filament_area == doctest::Approx(expected).epsilon(0.10));
  }
  // The estimate reads the arcs back: the same motion, give or take the corners they smooth.
  CHECK(estimate_gcode(arcs.text, "arcs").seconds == doctest::Approx(lines.seconds).epsilon(0.05));
  CHECK(arcs.filament_mm == doctest::Approx(lines.filament_mm).epsilon(0.01));
  // GPX has no arcs: the Sailfish flavour writes none, whatever the profile says.
  PrinterProfile replicator = *builtin_printer("replicator2x");
  replicator.arc_fitting = true;
  Mesh centred = tube;
  place_mesh(centred, {});
  const std::string sailfish = write_gcode(generate_toolpaths(centred, z, {}), replicator, {}).text;
  CHECK(sailfish.find("\nG2 ") == std::string::npos);
  CHECK(sailfish.find("\nG3 ") == std::string::npos);
}

TEST_CASE("the stream: a written file's busiest second fits a 115,200-baud link, and starves a slow one") {
  PrinterProfile printer = *builtin_printer("generic-i3");
  const auto layers = generate_toolpaths(box_on_bed(printer, 20, 20, 2), {0, 0.2, 0.4, 0.6, 0.8, 1.0}, {});
  const GcodeResult g = write_gcode(layers, printer, {});
  CHECK(g.stream.baud == 115200);
  CHECK(g.stream.peak_commands_per_second > 0);
  CHECK(g.stream.link_commands_per_second > g.stream.peak_commands_per_second);
  CHECK_FALSE(g.stream.starves());
  printer.baud = 1200;  // 120 bytes a second: a few lines
  CHECK(write_gcode(layers, printer, {}).stream.starves());
}

TEST_CASE("a cancelled token stops the G-code writer with Cancelled (a job's cancel, issue 32 item 17)") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  const auto layers = generate_toolpaths(box_on_bed(printer, 20, 20, 6), variable_plan(), {});
  CancelToken token;
  GcodeSettings gs;
  gs.cancel = &token;
  CHECK_NOTHROW(write_gcode(layers, printer, gs));
  token.cancel();
  CHECK_THROWS_AS(write_gcode(layers, printer, gs), Cancelled);
}
