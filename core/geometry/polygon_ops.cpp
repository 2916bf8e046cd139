// The one file that includes Clipper (libpolyclipping): conversion at the boundary, nonzero
// fill everywhere so that mesh sections (outer rings CCW, holes CW) mean what they say.
#include "core/geometry/polygon_ops.hpp"

#include <algorithm>
#include <cmath>
#include <polyclipping/clipper.hpp>

namespace salient::core {
namespace {

constexpr double scale = 1e5;  // 10 nm per unit

ClipperLib::Paths to_paths(const Polygons& polygons) {
  ClipperLib::Paths paths;
  paths.reserve(polygons.size());
  for (const Polygon& ring : polygons) {
    if (ring.size() < 3) continue;
    ClipperLib::Path path;
    path.reserve(ring.size());
    for (const Point2& p : ring)
      path.push_back({static_cast<ClipperLib::cInt>(std::llround(p.x * scale)),
                      static_cast<ClipperLib::cInt>(std::llround(p.y * scale))});
    paths.push_back(std::move(path));
  }
  return paths;
}

Polygon to_polygon(const ClipperLib::Path& path) {
  Polygon ring;
  ring.reserve(path.size());
  for (const ClipperLib::IntPoint& p : path) ring.push_back({p.X / scale, p.Y / scale});
  return ring;
}

Polygons to_polygons(const ClipperLib::Paths& paths) {
  Polygons out;
  out.reserve(paths.size());
  for (const ClipperLib::Path& p : paths) out.push_back(to_polygon(p));
  return out;
}

ClipperLib::Paths execute(ClipperLib::ClipType type, const Polygons& a, const Polygons* b) {
  ClipperLib::Clipper clipper;
  clipper.AddPaths(to_paths(a), ClipperLib::ptSubject, true);
  if (b) clipper.AddPaths(to_paths(*b), ClipperLib::ptClip, true);
  ClipperLib::Paths solution;
  clipper.Execute(type, solution, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return solution;
}

// The result as contours with their holes (Clipper's PolyTree).
std::vector<ExPolygon> execute_ex(ClipperLib::ClipType type, const Polygons& a, const Polygons* b) {
  ClipperLib::Clipper clipper;
  clipper.AddPaths(to_paths(a), ClipperLib::ptSubject, true);
  if (b) clipper.AddPaths(to_paths(*b), ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  clipper.Execute(type, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  std::vector<ExPolygon> out;
  // Outer nodes at even depth, their holes as children; islands inside holes recurse.
  std::vector<const ClipperLib::PolyNode*> stack(tree.Childs.begin(), tree.Childs.end());
  while (!stack.empty()) {
    const ClipperLib::PolyNode* outer = stack.back();
    stack.pop_back();
    ExPolygon ex{to_polygon(outer->Contour), {}};
    for (const ClipperLib::PolyNode* hole : outer->Childs) {
      ex.holes.push_back(to_polygon(hole->Contour));
      for (const ClipperLib::PolyNode* island : hole->Childs) stack.push_back(island);
    }
    out.push_back(std::move(ex));
  }
  return out;
}

double area_of(const ClipperLib::Paths& paths) {
  double a = 0;
  for (const ClipperLib::Path& p : paths) a += ClipperLib::Area(p);
  return a / (scale * scale);
}

}  // namespace

double covered_area(const Polygons& polygons) {
  return area_of(execute(ClipperLib::ctUnion, polygons, nullptr));
}

double intersection_area(const Polygons& a, const Polygons& b) {
  return area_of(execute(ClipperLib::ctIntersection, a, &b));
}

double xor_area(const Polygons& a, const Polygons& b) {
  return std::max(0.0, covered_area(a) + covered_area(b) - 2 * intersection_area(a, b));
}

Polygons union_of(const Polygons& polygons) {
  return to_polygons(execute(ClipperLib::ctUnion, polygons, nullptr));
}
Polygons intersection_of(const Polygons& a, const Polygons& b) {
  return to_polygons(execute(ClipperLib::ctIntersection, a, &b));
}
Polygons difference_of(const Polygons& a, const Polygons& b) {
  return to_polygons(execute(ClipperLib::ctDifference, a, &b));
}

std::vector<ExPolygon> union_ex(const Polygons& polygons) {
  return execute_ex(ClipperLib::ctUnion, polygons, nullptr);
}

std::vector<ExPolygon> difference_ex(const Polygons& a, const Polygons& b) {
  return execute_ex(ClipperLib::ctDifference, a, &b);
}

Polygons offset(const Polygons& polygons, double delta) {
  ClipperLib::ClipperOffset co(3.0);
  co.AddPaths(to_paths(polygons), ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
  ClipperLib::Paths solution;
  co.Execute(solution, delta * scale);
  return to_polygons(solution);
}

Polylines clip_lines(const Polylines& lines, const Polygons& region) {
  ClipperLib::Clipper clipper;
  for (const Polyline& line : lines) {
    if (line.size() < 2) continue;
    ClipperLib::Path path;
    for (const Point2& p : line)
      path.push_back({static_cast<ClipperLib::cInt>(std::llround(p.x * scale)),
                      static_cast<ClipperLib::cInt>(std::llround(p.y * scale))});
    clipper.AddPath(path, ClipperLib::ptSubject, false);
  }
  clipper.AddPaths(to_paths(region), ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  clipper.Execute(ClipperLib::ctIntersection, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  ClipperLib::Paths open;
  ClipperLib::OpenPathsFromPolyTree(tree, open);
  return to_polygons(open);
}

Polygons to_polygons(const std::vector<ExPolygon>& expolygons) {
  Polygons out;
  for (const ExPolygon& e : expolygons) {
    out.push_back(e.contour);
    out.insert(out.end(), e.holes.begin(), e.holes.end());
  }
  return out;
}

}  // namespace salient::core
