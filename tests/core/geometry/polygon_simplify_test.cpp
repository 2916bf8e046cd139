// Douglas–Peucker on closed rings: the Hausdorff bound both ways on real model sections, no ring
// collapsed or dropped, small features kept.
#include "core/geometry/polygon_simplify.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "core/geometry/mesh_section.hpp"
#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/placement.hpp"
#include "tests/core/geometry/segment_distance.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;
using salient::test::segment_distance;

namespace {

double ring_distance(const Point2& p, const Polygon& ring) {
  double d = 1e300;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i)
    d = std::min(d, segment_distance(p, ring[i], ring[(i + 1) % n]));
  return d;
}

// Points of a ring for a Hausdorff check: its vertices and points along each edge.
std::vector<Point2> samples(const Polygon& ring) {
  std::vector<Point2> out;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Point2 &a = ring[i], &b = ring[(i + 1) % n];
    for (double t : {0.0, 0.25, 0.5, 0.75}) out.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
  }
  return out;
}

double hausdorff(const Polygon& a, const Polygon& b) {
  double d = 0;
  for (const Point2& p : samples(a)) d = std::max(d, ring_distance(p, b));
  for (const Point2& p : samples(b)) d = std::max(d, ring_distance(p, a));
  return d;
}

// Whether `sub` is `ring` with some vertices left out, in order (cyclically from ring[0]).
bool is_subsequence(const Polygon& sub, const Polygon& ring) {
  std::size_t k = 0;
  for (const Point2& p : ring)
    if (k < sub.size() && p == sub[k]) ++k;
  return k == sub.size();
}

Polygon circle(double cx, double cy, double r, int n, bool ccw = true) {
  Polygon ring;
  for (int i = 0; i < n; ++i) {
    const double a = (ccw ? 1 : -1) * 2 * M_PI * i / n;
    ring.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
  }
  return ring;
}

}  // namespace

TEST_CASE("on real model sections: within the tolerance both ways, no ring dropped, fewer vertices") {
  const double tolerance = 0.0125;
  for (const char* name : {"stanford-bunny.obj", "spot.obj", "fandisk.obj", "igea.ply"}) {
    CAPTURE(name);
    Mesh mesh = load_mesh(salient::test::model_path(name)).mesh;
    PlacementOptions o;
    o.up = UpAxis::y;
    o.target_height = 80;
    place_mesh(mesh, o);
    std::vector<double> heights;
    for (double z = 0.5; z < 80; z += 2.5) heights.push_back(z);
    std::size_t before = 0, after = 0, rings = 0;
    for (const Section& s : section_mesh(mesh, heights)) {
      const Polygons simple = simplify_polygons(s.loops, tolerance);
      REQUIRE(simple.size() == s.loops.size());
      for (std::size_t i = 0; i < s.loops.size(); ++i) {
        const Polygon &ring = s.loops[i], &out = simple[i];
        if (ring.size() < 3) continue;
        ++rings;
        before += ring.size(), after += out.size();
        CHECK(out.size() >= 3);
        CHECK(is_subsequence(out, ring));
        CHECK(hausdorff(ring, out) <= tolerance + 1e-9);
        // A ring keeps its orientation (outline or hole) unless it is thinner than the tolerance.
        const double area = signed_area(ring);
        if (std::fabs(area) > 1) CHECK((signed_area(out) > 0) == (area > 0));
      }
    }
    CHECK(rings > 0);
    CHECK(after < before);
    MESSAGE(std::string(name) << ": " << before << " vertices -> " << after << " in " << rings << " rings");
  }
}

TEST_CASE("small features keep their shape and stay closed") {
  // A 0.6 mm pin (64 vertices): a polygon close to the circle, not a sliver or a dot.
  const Polygon pin = circle(10, 10, 0.3, 64);
  const Polygon out = simplify_polygon(pin, 0.0125);
  CHECK(out.size() >= 6);
  CHECK(out.size() < pin.size());
  CHECK(signed_area(out) == doctest::Approx(signed_area(pin)).epsilon(0.1));
  CHECK(hausdorff(pin, out) <= 0.0125 + 1e-12);
  // A hole (clockwise) stays a hole.
  CHECK(signed_area(simplify_polygon(circle(0, 0, 0.3, 64, false), 0.0125)) < 0);
  // Smaller than the tolerance altogether: still a triangle, never dropped.
  const Polygon speck = circle(5, 5, 0.004, 12);
  CHECK(simplify_polygon(speck, 0.0125).size() == 3);
  const Polygon sliver{{0, 0}, {1, 0}, {2, 0.001}, {1, 0.002}, {0, 0.001}};
  const Polygon thin = simplify_polygon(sliver, 0.0125);
  CHECK(thin.size() == 3);
  CHECK(hausdorff(sliver, thin) <= 0.0125 + 1e-12);
}

TEST_CASE("a square keeps its corners, collinear points go, tolerance 0 changes nothing") {
  const Polygon square{{0, 0}, {5, 0}, {10, 0}, {10, 5}, {10, 10}, {5, 10.001}, {0, 10}, {0, 5}};
  const Polygon out = simplify_polygon(square, 0.0125);
  CHECK(out == Polygon{{0, 0}, {10, 0}, {10, 10}, {0, 10}});
  CHECK(simplify_polygon(square, 0) == square);
  const Polygon triangle{{0, 0}, {1, 0}, {0, 1}};
  CHECK(simplify_polygon(triangle, 10) == triangle);
}
