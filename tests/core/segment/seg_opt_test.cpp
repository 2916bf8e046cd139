// SegOpt (paper §5): the cut is kept only where it saves time; the regions it makes obey the
// printer's limits at every seam and each keeps its quality budget; the G-code prints each region
// at its own heights.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "core/gcode/gcode_writer.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/segment/mesh_split.hpp"
#include "core/segment/regions_svg.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

constexpr double radius = 40;

// A sphere of radius 40 mm on the bed (a print of an hour or more: small ones are all cooling time), at the
// middle of generic-i3's bed.
Mesh sphere_on_bed(const PrinterProfile& printer) {
  Mesh m = salient::test::uv_sphere(48, 96);
  for (Vec3& p : m.positions) p = Vec3{printer.bed_center_x(), printer.bed_center_y(), radius} + p * radius;
  return m;
}

// Saliency 1 on the −x half, `low` on the +x half.
std::vector<float> halves(const Mesh& m, double cx, float low) {
  std::vector<float> s(m.vertex_count());
  for (std::size_t v = 0; v < s.size(); ++v) s[v] = m.positions[v].x < cx ? 1.0f : low;
  return s;
}

struct Fixture {
  PrinterProfile printer = *builtin_printer("generic-i3");
  Mesh mesh = sphere_on_bed(printer);
  SlicingParams params{printer.min_layer, printer.max_layer, 0.01};
  std::vector<float> saliency;
  std::unique_ptr<ZProfile> profile;
  std::unique_ptr<Planner> planner = make_planner("exact");
  RegionSliceSettings settings;
  int first_cells = 0;  // the fixed first layer

  SegOptResult run(std::vector<float> s, const SegOptOptions& options = {}) {
    saliency = std::move(s);
    profile = std::make_unique<ZProfile>(ZProfile::build(mesh, saliency, params));
    const SegOptInput in{mesh, saliency, *profile, Metric::area, *planner, 0.05, 1, nullptr, {}, first_cells};
    return seg_opt(
        in,
        [&](const std::vector<PlanRegion>& r) {
          return region_print_seconds(mesh, *profile, r, settings, printer);
        },
        options);
  }
};

// The half-salient sphere, segmented once for the tests that only read the result.
struct HalfSalient {
  Fixture f;
  SegOptResult r = f.run(halves(f.mesh, f.printer.bed_center_x(), 0.02f));
};
HalfSalient& half_salient() {
  static HalfSalient h;
  return h;
}

}  // namespace

TEST_CASE("a sphere with one salient half is cut between its halves, and the cut saves time") {
  Fixture& f = half_salient().f;
  const SegOptResult& r = half_salient().r;
  INFO(r.note);
  REQUIRE(r.cut);
  REQUIRE(r.seam);
  CHECK(std::fabs(r.seam->plane.ny) < 0.1);  // a plane across x
  CHECK(std::fabs(r.seam->plane.offset * r.seam->plane.nx - f.printer.bed_center_x()) < 0.1 * radius);
  CHECK(r.parts_seconds / r.whole_seconds < 0.85);
  CHECK(r.seconds < r.whole_seconds);
  CHECK(check_regions(*f.profile, r.regions) == "");
  int sides = 0;
  for (const PlanRegion& region : r.regions) sides += region.side >= 0;
  CHECK(sides >= 2);
  MESSAGE("sphere, one salient half: " << r.note << "; " << r.whole_seconds / 60 << " min whole, "
                                       << r.parts_seconds / 60 << " min parts, " << r.seconds / 60
                                       << " min segmented");
}

TEST_CASE("each region of a segmented plan keeps its budget, and the parts of a slab keep the slab's") {
  Fixture& f = half_salient().f;
  const SegOptResult& r = half_salient().r;
  REQUIRE(r.cut);
  const auto parts = split_mesh(f.mesh, f.saliency, r.seam->plane);
  std::vector<ZProfile> part;
  for (int s = 0; s < 2; ++s)
    part.push_back(ZProfile::build(parts[s].mesh, parts[s].values, f.params, {}, f.profile->height()));
  for (const PlanRegion& region : r.regions) {
    // E recomputed from scratch on the region's own slab and part.
    const ZProfile slab =
        (region.side < 0 ? *f.profile : part[region.side]).window(region.first_cell, region.last_cell);
    const Objective objective(slab, Metric::area);
    LayerPlan local;
    for (int b : region.plan.boundaries) local.boundaries.push_back(b - region.first_cell);
    CHECK(check_plan(slab, local) == "");
    const double e = objective.error(local);
    CHECK(e == doctest::Approx(region.error).epsilon(1e-9));
    CHECK(e <= region.epsilon * (1 + 1e-9) + 1e-12);
    const double slab_budget =
        Objective(f.profile->window(region.first_cell, region.last_cell), Metric::area).epsilon(0.05);
    if (region.side < 0) {
      CHECK(region.epsilon == doctest::Approx(slab_budget));
    } else {
      double shared = 0;  // the two parts of this slab
      for (const PlanRegion& other : r.regions)
        if (other.first_cell == region.first_cell && other.last_cell == region.last_cell)
          shared += other.error;
      CHECK(shared <= slab_budget * (1 + 1e-9));
    }
  }
}

TEST_CASE("a segmented plan starts with the printer's fixed first layer, on both sides of the cut") {
  Fixture f;
  f.first_cells = 20;  // generic-i3's 0.2 mm on the 0.01 mm grid; free layers start at α = 0.1 mm
  const SegOptResult r = f.run(halves(f.mesh, f.printer.bed_center_x(), 0.02f));
  INFO(r.note);
  REQUIRE(r.cut);
  CHECK(check_regions(*f.profile, r.regions) == "");
  int on_bed = 0;
  for (const PlanRegion& region : r.regions) {
    if (region.first_cell != 0) continue;
    ++on_bed;
    REQUIRE(region.plan.boundaries.size() > 1);
    CHECK(region.plan.boundaries[1] == 20);
    CHECK(region.error <= region.epsilon * (1 + 1e-9) + 1e-12);
  }
  CHECK(on_bed >= 1);
  for (const PlanRegion& part : r.parts) CHECK(part.plan.boundaries[1] == 20);  // T1 + T2's plans too
}

TEST_CASE("a sphere is not cut: uniform saliency, and the saliency of its own shape") {
  Fixture f;
  for (float low : {1.0f, 0.5f}) {
    // 0.5: both halves alike after all once the budget is shared
    const SegOptResult r = f.run(std::vector<float>(f.mesh.vertex_count(), low));
    INFO(r.note);
    CHECK_FALSE(r.cut);
    REQUIRE(r.regions.size() == 1);
    CHECK(r.regions[0].side == -1);
    CHECK(r.seconds == r.whole_seconds);
  }
}

TEST_CASE("the seam rule: touching regions print the same heights or heights at least α apart") {
  Fixture f;
  f.run(std::vector<float>(f.mesh.vertex_count(), 1.0f));
  const ZProfile& p = *f.profile;
  const int m = p.cells(), a = p.min_cells();
  PlanRegion left, right;
  left.side = 0, right.side = 1;
  left.last_cell = right.last_cell = m;
  left.plan = uniform_plan(p, (p.fewest_layers() + p.most_layers()) / 2);
  right.plan = left.plan;
  CHECK(check_regions(p, {left, right}) == "");
  // Move one of right's boundaries a few cells: now a sliver against left's layer.
  right.plan.boundaries[1] += a / 3;
  CHECK(check_regions(p, {left, right}).find("closer than") != std::string::npos);
  right.plan = left.plan;
  // seam_allowed marks exactly the cells that keep the rule.
  const std::vector<char> allowed = seam_allowed(p, 0, m, {&left});
  for (int k = 0; k <= m; ++k) {
    bool ok = true;
    for (int b : left.plan.boundaries) ok = ok && (k == b || std::abs(k - b) >= a);
    if (k == 0 || k == m) ok = true;
    CHECK(static_cast<bool>(allowed[k]) == ok);
  }
  // A height covered twice, or not at all, is refused.
  PlanRegion whole;
  whole.last_cell = m;
  whole.plan = left.plan;
  CHECK(check_regions(p, {whole, left, right}).find("exactly once") != std::string::npos);
  CHECK(check_regions(p, {left}).find("exactly once") != std::string::npos);
}

TEST_CASE("the G-code of a segmented plan prints each region at its own heights") {
  Fixture& f = half_salient().f;
  const SegOptResult& r = half_salient().r;
  REQUIRE(r.cut);
  const auto layers = region_toolpaths(f.mesh, *f.profile, r.regions, f.settings);
  // Every region's layer tops are printed heights, and nothing else is.
  std::set<long> want;
  for (const PlanRegion& region : r.regions)
    for (std::size_t i = 1; i < region.plan.boundaries.size(); ++i)
      want.insert(std::lround(f.profile->z(region.plan.boundaries[i]) * 1000));
  const std::string gcode = write_gcode(layers, f.printer, {}).text;
  std::set<long> printed;
  std::istringstream in(gcode);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(";Z:", 0) == 0) printed.insert(std::lround(std::stod(line.substr(3)) * 1000));
  for (long z : printed) CHECK(want.count(z) == 1);
  // A region's layer may be empty (above its part of the model) and is then not printed; all the
  // others are.
  CHECK(printed.size() >= want.size() * 9 / 10);
  // Each side's paths extrude for the side's own layer height: thin on the salient side, thick on
  // the other, in the same printed layers.
  double thin = 1, thick = 0;
  for (const LayerToolpaths& l : layers)
    for (const ExtrusionPath& path : l.paths)
      if (path.role == ExtrusionRole::external_perimeter)
        thin = std::min(thin, path.height), thick = std::max(thick, path.height);
  CHECK(thin < thick - 0.1);
  CHECK(regions_svg(*f.profile, r.regions, "sphere").find("regions") != std::string::npos);
}

TEST_CASE("recursively: a part is cut again where that saves time, and the nested regions tile the model") {
  // An ellipsoid 2.2 times longer in x than wide, salient only in its middle third: the first
  // cut takes off one plain end, the second (inside the other part) the other end. τ = 0.95:
  // with the paper's 0.85 one plain end of this size is not worth a seam.
  Fixture f;
  const double cx = f.printer.bed_center_x(), half_length = 2.2 * radius;
  for (Vec3& p : f.mesh.positions) p.x = cx + (p.x - cx) * 2.2;
  std::vector<float> s(f.mesh.vertex_count());
  for (std::size_t v = 0; v < s.size(); ++v)
    s[v] = std::fabs(f.mesh.positions[v].x - cx) < half_length / 3 ? 1.0f : 0.02f;
  SegOptOptions options;
  options.tau = 0.95;
  const SegOptResult once = f.run(s, options);
  INFO(once.note);
  REQUIRE(once.cut);
  options.depth = 2;
  const SegOptResult twice = f.run(s, options);
  INFO(twice.note);
  REQUIRE(twice.cut);
  CHECK(check_regions(*f.profile, twice.regions) == "");
  bool nested = false;
  for (const PlanRegion& r : twice.regions) nested = nested || !r.sub.empty();
  CHECK(nested);
  CHECK(twice.seconds < once.seconds);
  for (const PlanRegion& r : twice.regions) CHECK(r.error <= r.epsilon * (1 + 1e-9) + 1e-12);
  // The printed heights are still exactly the regions' heights.
  const auto layers = region_toolpaths(f.mesh, *f.profile, twice.regions, f.settings);
  const std::vector<double> heights = printed_heights(*f.profile, twice.regions);
  for (const LayerToolpaths& l : layers)
    CHECK(
        std::any_of(heights.begin(), heights.end(), [&](double z) { return std::fabs(z - l.z_top) < 1e-6; }));
  MESSAGE("recursive: " << once.seconds / 60 << " min at depth 1, " << twice.seconds / 60
                        << " min at depth 2; " << twice.note);
}

TEST_CASE("find_cuts: the best planes by seam cost, one per direction, the first is find_cut's") {
  Fixture f;
  const std::vector<float> s = halves(f.mesh, f.printer.bed_center_x(), 0.02f);
  const std::vector<SeamCandidate> five = find_cuts(f.mesh, s, 5);
  REQUIRE(five.size() == 5);
  const auto best = find_cut(f.mesh, s);
  REQUIRE(best);
  CHECK(five[0].cost == best->cost);
  CHECK(five[0].plane.offset == best->plane.offset);
  for (std::size_t i = 1; i < five.size(); ++i) {
    CHECK(five[i - 1].cost <= five[i].cost);
    for (std::size_t j = 0; j < i; ++j)  // different directions
      CHECK(std::fabs(five[i].plane.nx * five[j].plane.nx + five[i].plane.ny * five[j].plane.ny) < 1 - 1e-9);
    CHECK(five[i].share >= 0.1);
  }
  CHECK(find_cuts(f.mesh, s, 0).empty());
}
