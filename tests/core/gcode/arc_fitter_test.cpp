// Arc fitting: every input vertex and segment within the tolerance of the fitted path, arcs no
// more than half a turn, circles become a few arcs, corners and straight runs stay lines.
#include "core/gcode/arc_fitter.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "core/geometry/mesh_section.hpp"
#include "core/geometry/polygon_simplify.hpp"
#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/placement.hpp"
#include "tests/core/geometry/segment_distance.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;
using salient::test::segment_distance;

namespace {

// Points along the fitted moves from `start`, close enough that the trace's own chords stray
// less than a micrometre from an arc.
std::vector<Point2> trace(const Point2& start, const std::vector<PathMove>& moves) {
  std::vector<Point2> out{start};
  Point2 at = start;
  for (const PathMove& m : moves) {
    const int steps = std::max(64, static_cast<int>(std::ceil(m.length / 0.05)));
    if (!m.arc) {
      for (int k = 1; k <= steps; ++k)
        out.push_back(
            {at.x + k / double(steps) * (m.to.x - at.x), at.y + k / double(steps) * (m.to.y - at.y)});
    } else {
      const double r = std::hypot(at.x - m.center.x, at.y - m.center.y);
      const double a0 = std::atan2(at.y - m.center.y, at.x - m.center.x);
      const double sweep = m.length / r * (m.ccw ? 1 : -1);
      for (int k = 1; k <= steps; ++k)
        out.push_back({m.center.x + r * std::cos(a0 + k / double(steps) * sweep),
                       m.center.y + r * std::sin(a0 + k / double(steps) * sweep)});
    }
    at = m.to;
  }
  return out;
}

double polyline_distance(const Point2& p, const std::vector<Point2>& line) {
  double d = 1e300;
  for (std::size_t i = 0; i + 1 < line.size(); ++i)
    d = std::min(d, segment_distance(p, line[i], line[i + 1]));
  return d;
}

// The fitted path against the input, both ways.
void check_fit(const std::vector<Point2>& points, const std::vector<PathMove>& moves, double tolerance) {
  REQUIRE(!moves.empty());
  CHECK(moves.back().to == points.back());
  const std::vector<Point2> traced = trace(points.front(), moves);
  for (const Point2& p : traced) CHECK(polyline_distance(p, points) <= tolerance + 1e-6);
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    CHECK(polyline_distance(points[i], traced) <= tolerance + 1e-6);
    const Point2 mid{(points[i].x + points[i + 1].x) / 2, (points[i].y + points[i + 1].y) / 2};
    CHECK(polyline_distance(mid, traced) <= tolerance + 1e-6);
  }
  for (const PathMove& m : moves) {
    if (!m.arc) continue;
    // The move ends on one of the input's vertices, and sweeps less than half a turn.
    CHECK(std::find(points.begin(), points.end(), m.to) != points.end());
    const double r = std::hypot(m.to.x - m.center.x, m.to.y - m.center.y);
    CHECK(m.length < M_PI * r + 1e-9);
  }
}

std::vector<Point2> circle(double r, int n, bool ccw) {
  std::vector<Point2> out;
  for (int i = 0; i <= n; ++i) {
    const double a = (ccw ? 1 : -1) * 2 * M_PI * i / n;
    out.push_back({50 + r * std::cos(a), 50 + r * std::sin(a)});
  }
  return out;
}

}  // namespace

TEST_CASE("a circle of many segments becomes a few arcs, either way round") {
  for (bool ccw : {true, false}) {
    CAPTURE(ccw);
    const auto points = circle(10, 200, ccw);
    const auto moves = fit_arcs(points, 0.0125);
    CHECK(moves.size() <= 4);
    for (const PathMove& m : moves) {
      CHECK(m.arc);
      CHECK(m.ccw == ccw);
      CHECK(std::hypot(m.center.x - 50, m.center.y - 50) < 1e-6);
    }
    double length = 0;
    for (const PathMove& m : moves) length += m.length;
    CHECK(length == doctest::Approx(2 * M_PI * 10).epsilon(1e-3));
    check_fit(points, moves, 0.0125);
  }
}

TEST_CASE("corners and straight runs stay lines") {
  const std::vector<Point2> square{{0, 0}, {10, 0}, {10, 10}, {0, 10}, {0, 0}};
  const auto moves = fit_arcs(square, 0.0125);
  REQUIRE(moves.size() == 4);
  for (const PathMove& m : moves) CHECK_FALSE(m.arc);
  const std::vector<Point2> zigzag{{0, 0}, {1, 0.5}, {2, 0}, {3, 0.5}, {4, 0}};
  for (const PathMove& m : fit_arcs(zigzag, 0.0125)) CHECK_FALSE(m.arc);
  CHECK(fit_arcs({{0, 0}}, 0.0125).empty());
}

TEST_CASE("on real model sections, simplified as the toolpaths are: within the tolerance, fewer moves") {
  const double tolerance = 0.0125;
  for (const char* name : {"stanford-bunny.obj", "spot.obj", "fandisk.obj"}) {
    CAPTURE(std::string(name));
    Mesh mesh = load_mesh(salient::test::model_path(name)).mesh;
    PlacementOptions o;
    o.up = UpAxis::y;
    o.target_height = 80;
    place_mesh(mesh, o);
    std::vector<double> heights;
    for (double z = 1; z < 80; z += 7.5) heights.push_back(z);
    std::size_t segments = 0, moves = 0;
    for (const Section& s : section_mesh(mesh, heights))
      for (Polygon ring : simplify_polygons(s.loops, tolerance)) {
        ring.push_back(ring.front());  // closed, as the writer traces a loop
        const auto fitted = fit_arcs(ring, tolerance);
        check_fit(ring, fitted, tolerance);
        segments += ring.size() - 1, moves += fitted.size();
      }
    CHECK(moves < segments);
    MESSAGE(std::string(name) << ": " << segments << " segments -> " << moves << " moves");
  }
}
