// Automatic orientation: candidate directions, bed contact, eq. 11–13, the rotation to +Z, and
// the whole choice on a bar that should be laid down.
#include "core/orient/orientation.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <fstream>

#include "core/mesh/placement.hpp"
#include "core/pipeline/auto_orient.hpp"
#include "core/printer/printer_profile.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"
#include "tests/core/orient/test_solids.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::core;
using salient::test::rotate;

namespace {

Vec3 unit(const Vec3& v) {
  return v / norm(v);
}

std::string off_text(const Mesh& m) {
  std::string s =
      "OFF\n" + std::to_string(m.vertex_count()) + " " + std::to_string(m.triangle_count()) + " 0\n";
  for (const Vec3& p : m.positions)
    s += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  for (const Triangle& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

}  // namespace

TEST_CASE("a turned box: the three candidates are its face normals") {
  Mesh m = salient::test::box(10, 20, 30);
  const Vec3 axis{0.3, -0.5, 0.8};
  const double angle = 0.7;
  for (Vec3& p : m.positions) p = rotate(p, axis, angle);
  const auto candidates = candidate_directions(m);
  const std::array<Vec3, 3> faces = {rotate({1, 0, 0}, axis, angle), rotate({0, 1, 0}, axis, angle),
                                     rotate({0, 0, 1}, axis, angle)};
  for (const Vec3& f : faces) {
    double best = 0;
    for (const Vec3& c : candidates) best = std::max(best, std::abs(dot(c, f)));
    CHECK(best > 0.999);
  }
  // Orthonormal.
  CHECK(std::abs(dot(candidates[0], candidates[1])) < 1e-9);
  CHECK(std::abs(dot(candidates[1], candidates[2])) < 1e-9);
  CHECK(std::abs(norm(candidates[2]) - 1) < 1e-9);
  // The heaviest cluster first: the faces normal to x (20 × 30 mm, twice) outweigh the others.
  CHECK(std::abs(dot(candidates[0], faces[0])) > 0.999);
}

TEST_CASE("bed contact: the face that lies on the bed, and the sign that puts the most area down") {
  Mesh m = salient::test::box(10, 20, 60);
  CHECK(bed_contact_area(m, {0, 0, 1}, 0.05) == doctest::Approx(200));
  CHECK(bed_contact_area(m, {1, 0, 0}, 0.05) == doctest::Approx(1200));
  CHECK(bed_contact_area(m, {0, 0, -1}, 0.05) == doctest::Approx(200));
  // A wedge: a square base at the bottom, a ridge on top (touching the bed only along a line when upside
  // down).
  Mesh wedge;
  wedge.positions = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {0, 5, 8}, {10, 5, 8}};
  wedge.triangles = {{0, 2, 1}, {0, 3, 2}, {0, 1, 5}, {0, 5, 4}, {3, 4, 5}, {3, 5, 2}, {0, 4, 3}, {1, 2, 5}};
  CHECK(bed_contact_area(wedge, {0, 0, 1}, 0.05) == doctest::Approx(100));
  // Upside down, the strip of its two slopes within 0.05 mm of the ridge: 2 × 10 × (5 × 0.05 / 8).
  CHECK(bed_contact_area(wedge, {0, 0, -1}, 0.05) == doctest::Approx(0.625));
  CHECK(pick_up_sign(wedge, {0, 0, -1}).z == doctest::Approx(1));
  CHECK(pick_up_sign(wedge, {0, 0, 1}).z == doctest::Approx(1));
}

TEST_CASE("an axis is signed so that a four-legged animal stands on its legs, not on its round back") {
  // A round body (an ellipsoid 40 long, radius 8, along x) on four 2 × 2 × 15 mm legs: the hooves
  // and the back touch the bed about as much, neither is a base. Upright, the belly overhangs 15 mm
  // above the bed, on its back almost nothing does, so signing by support (as this did before) laid
  // the cow of the shared models on its back; the legs span a far wider footprint.
  std::vector<std::vector<Vec3>> rings;
  for (int k = 1; k < 40; ++k) {
    const double r = 8 * std::sin(M_PI * k / 40);
    rings.push_back(salient::test::ring(48, 0, 0, k, [r](double) { return r; }));
  }
  Mesh animal = salient::test::ring_stack(rings);
  for (Vec3& p : animal.positions) p = rotate(p, {0, 1, 0}, M_PI / 2) + Vec3{0, 0, 15 + 6};
  for (const Vec3 at : {Vec3{8, -5, 0}, Vec3{8, 3, 0}, Vec3{30, -5, 0}, Vec3{30, 3, 0}}) {
    Mesh leg = salient::test::box(2, 2, 16);
    const auto base = static_cast<std::uint32_t>(animal.positions.size());
    for (const Vec3& p : leg.positions) animal.positions.push_back(p + at);
    for (Triangle t : leg.triangles) animal.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  CHECK(pick_up_sign(animal, {0, 0, 1}).z == doctest::Approx(1));
  CHECK(pick_up_sign(animal, {0, 0, -1}).z == doctest::Approx(1));
}

TEST_CASE("VolS (eq. 13): a box sliced in whole layers has its volume exactly, a sphere nearly") {
  const Mesh box = salient::test::box(10, 20, 6);
  std::vector<double> z;
  for (int i = 0; i <= 30; ++i) z.push_back(0.2 * i);
  CHECK(volumetric_score(box, z) == doctest::Approx(1.0).epsilon(1e-9));
  Mesh sphere = salient::test::uv_sphere(48, 96);
  for (Vec3& p : sphere.positions) p = p * 10 + Vec3{0, 0, 10};
  std::vector<double> coarse, fine;
  for (int i = 0; i <= 5; ++i) coarse.push_back(4.0 * i);
  for (int i = 0; i <= 100; ++i) fine.push_back(0.2 * i);
  const double c = volumetric_score(sphere, coarse), f = volumetric_score(sphere, fine);
  CHECK(f > 0.99);
  CHECK(c < f);  // thicker layers, larger error
  CHECK(volumetric_score(sphere, std::vector<double>{0}) == 0);
}

TEST_CASE("OS (eqs. 11-12) by hand") {
  std::vector<OrientationScore> cs(3);
  cs[0].minutes = 10, cs[1].minutes = 20, cs[2].minutes = 15;
  for (auto& c : cs) c.volume_score = 1;
  cs[0].contact_area = 0, cs[1].contact_area = 50, cs[2].contact_area = 100;
  const std::size_t best = score_orientations(cs, 1000);
  CHECK(cs[0].time_score == doctest::Approx(1));
  CHECK(cs[1].time_score == doctest::Approx(0));
  CHECK(cs[2].time_score == doctest::Approx(0.5));
  CHECK(cs[2].stability_score == doctest::Approx(0.1));
  CHECK(cs[0].score == doctest::Approx(0.6));
  CHECK(cs[1].score == doctest::Approx(0.315));
  CHECK(cs[2].score == doctest::Approx(0.48));
  CHECK(best == 0);
  std::vector<OrientationScore> same(2);  // equal times: both get TimeS 1, no division by zero
  same[0].minutes = same[1].minutes = 7;
  score_orientations(same, 0);
  CHECK(same[0].time_score == 1);
  CHECK(same[1].stability_score == 0);
}

TEST_CASE("turning a direction to +Z is a proper rotation") {
  for (const Vec3& d :
       {Vec3{0, 0, 1}, Vec3{0, 0, -1}, Vec3{1, 0, 0}, Vec3{0.2, -0.9, 0.3}, Vec3{-1e-9, 0, -1}}) {
    const Vec3 u = unit(d);
    const Vec3 z = turn_to_z(u, u);
    CHECK(z.x == doctest::Approx(0).epsilon(1e-9));
    CHECK(z.y == doctest::Approx(0).epsilon(1e-9));
    CHECK(z.z == doctest::Approx(1));
    const Vec3 a = turn_to_z({1, 0, 0}, u), b = turn_to_z({0, 1, 0}, u), c = turn_to_z({0, 0, 1}, u);
    CHECK(dot(a, cross(b, c)) == doctest::Approx(1));  // determinant +1: no mirror, volumes keep their sign
  }
  CHECK(parse_up_direction("0,-1,0.2"));
  for (const char* bad : {"1,2", "a,b,c", "0,0,0", "1,2,3,4", "1,,2", "nan,0,1", ""})
    CHECK_MESSAGE(!parse_up_direction(bad), bad);
  CHECK(parse_up_direction(direction_text({0.25, -0.5, 1}))->y == doctest::Approx(-0.5));
}

TEST_CASE("--up auto lays a long bar down: shorter, faster and steadier") {
  salient::test::ScratchDir dir("orient-bar");
  std::filesystem::create_directories(dir.path);
  const std::string file = (dir.path / "bar.off").string();
  std::ofstream(file) << off_text(salient::test::box(60, 8, 12));  // long along x in the file
  SliceSettings settings;
  settings.plan.mesh.model = file;
  settings.plan.mesh.up = "auto";
  const OrientationReport r = choose_orientation(settings, *builtin_printer("generic-i3"), {});
  REQUIRE(r.candidates.size() >= 3);
  const OrientationScore& best = r.candidates[r.best];
  CHECK(std::abs(best.up.x) < 1e-6);  // not standing on its end
  for (const auto& c : r.candidates) {
    CHECK(c.minutes > 0);
    CHECK(c.layers > 0);
    CHECK(c.volume_score > 0.99);
    if (std::abs(c.up.x) > 0.999) CHECK(c.minutes > best.minutes);
  }
  CHECK(best.stability_score > 0.25);  // lying on a 60 × 12 (720 mm²) or 60 × 8 face, of 2,592 mm² in all
  // Slicing with auto uses the choice, and says so.
  settings.toolpaths.infill_density = 0.1;
  const SliceResult sliced = slice_model(settings, *builtin_printer("generic-i3"), {});
  REQUIRE(sliced.orientation);
  CHECK(sliced.orientation->up == r.up);
  CHECK(sliced.z.back() < 13);  // printed lying down
}

namespace {

// `mesh` turned by an arbitrary rotation and written as OFF, for choose_orientation to load.
std::string write_turned(const salient::test::ScratchDir& dir, const std::string& name, Mesh mesh,
                         const Vec3& axis, double angle) {
  for (Vec3& p : mesh.positions) p = salient::test::rotate(p, axis, angle);
  const std::string file = (dir.path / (name + ".off")).string();
  std::ofstream(file) << off_text(mesh);
  return file;
}

double degrees_between(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(unit(a), unit(b)), -1.0, 1.0)) * 180 / M_PI;
}

}  // namespace

TEST_CASE(
    "a bolt's head, a bust's pedestal and a block's bottom, turned off the axes, are offered as bases") {
  const Vec3 axis{0.4, -0.7, 0.2};
  const double angle = 1.1;  // 63°
  const Vec3 base_up = salient::test::rotate({0, 0, 1}, axis, angle);
  for (Mesh m : {salient::test::bolt(), salient::test::bust(), salient::test::ramp_block()}) {
    for (Vec3& p : m.positions) p = salient::test::rotate(p, axis, angle);
    const std::vector<Vec3> bases = base_directions(m);
    REQUIRE(!bases.empty());
    CHECK(degrees_between(bases.front(), base_up) < 0.01);  // the largest base, exactly
    const std::vector<Vec3> ups = candidate_ups(m);
    CHECK(ups.size() <= 6);
    CHECK(std::count_if(ups.begin(), ups.end(),
                        [&](const Vec3& u) { return degrees_between(u, base_up) < 0.01; }) == 1);
  }
}

TEST_CASE("bases: a box's six faces, none on a sphere, none a model would topple off") {
  CandidateOptions o;
  o.max_bases = 6;
  const std::vector<Vec3> box = base_directions(salient::test::box(10, 20, 30), o);
  CHECK(box.size() == 6);
  CHECK(std::abs(box.front().x) == doctest::Approx(1));  // the 20 × 30 faces first
  Mesh sphere = salient::test::uv_sphere(48, 96);
  for (Vec3& p : sphere.positions) p = p * 40;
  CHECK(base_directions(sphere).empty());
  // A T: a bar 40 mm wide on a stem 6 mm wide. The bar's ends are flat and at the bottom when
  // turned down, but the T's centre of mass is far beside them: it would fall over.
  const auto rect = [](double x0, double x1, double z) {
    return std::vector<Vec3>{{x0, 0, z}, {x1, 0, z}, {x1, 10, z}, {x0, 10, z}};
  };
  const Mesh tee =
      salient::test::ring_stack({rect(-3, 3, 0), rect(-3, 3, 20), rect(-20, 20, 20), rect(-20, 20, 25)});
  o.min_share = 0;
  o.max_bases = 100;
  const std::vector<Vec3> rests = base_directions(tee, o);
  const auto offered = [&](const Vec3& up) {
    return std::any_of(rests.begin(), rests.end(),
                       [&](const Vec3& u) { return degrees_between(u, up) < 10; });
  };
  CHECK(offered({0, 0, 1}));   // on its stem
  CHECK(offered({0, 0, -1}));  // on its bar
  CHECK(offered({0, 1, 0}));   // on its side
  CHECK(!offered({1, 0, 0}));  // on an end of the bar
  CHECK(!offered({-1, 0, 0}));
}

TEST_CASE("--up auto stands a boat-like block and a bolt on their bases, however they come turned") {
  salient::test::ScratchDir dir("orient-bases");
  std::filesystem::create_directories(dir.path);
  const Vec3 axis{0.4, -0.7, 0.2};
  const double angle = 1.1;
  const Vec3 base_up = rotate({0, 0, 1}, axis, angle);
  // The ramp's k-means axes are 4.7° off its base (the rounded top pulls them over); the bolt's
  // are not, but its shank's end is also a base.
  for (const auto& [name, mesh] :
       {std::pair{"ramp", salient::test::ramp_block()}, {"bolt", salient::test::bolt()}}) {
    SliceSettings settings;
    settings.plan.mesh.model = write_turned(dir, name, mesh, axis, angle);
    settings.plan.mesh.up = "auto";
    settings.plan.saliency = SaliencyMethod::uniform;  // the choice is about shape: quicker so
    const OrientationReport r = choose_orientation(settings, *builtin_printer("generic-i3"), {});
    const OrientationScore& best = r.candidates[r.best];
    INFO(std::string(name), ": chose ", direction_text(best.up));
    CHECK(degrees_between(best.up, base_up) < 0.01);
    CHECK(best.stability_score > 0.05);  // it stands on its whole base
  }
}

TEST_CASE("--up auto stands the Stanford bunny on its feet, at print scale") {
  // The contact tolerance is in print millimetres: a scanned animal touches the bed at a few
  // specks whichever way up, and upside down it would hang over its back.
  SliceSettings settings;
  settings.plan.mesh.model = salient::test::model_path("stanford-bunny.obj");
  settings.plan.mesh.up = "auto";
  settings.plan.mesh.height = 80;
  settings.plan.saliency = SaliencyMethod::uniform;
  const OrientationReport r = choose_orientation(settings, *builtin_printer("generic-i3"), {});
  const OrientationScore& best = r.candidates[r.best];
  INFO("chose ", direction_text(best.up));
  CHECK(best.up.y > 0.95);  // +y is the bunny's up in the file
}
