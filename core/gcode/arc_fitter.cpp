// fit_arcs. A run p_i … p_j is tried on the circle through p_i, its middle vertex and p_j; it fits
// when the vertices advance round it one way by less than half a turn in all, and each segment
// is within the tolerance of its piece of the arc (sagitta plus radial error, below). Runs grow
// one vertex at a time while they fit.
#include "core/gcode/arc_fitter.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace salient::core {
namespace {

struct Circle {
  Point2 c;
  double r;
  bool ccw;
};

std::optional<Circle> circle_through(const Point2& a, const Point2& b, const Point2& c) {
  const double d = 2 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
  const double scale = std::hypot(c.x - a.x, c.y - a.y);
  if (!(std::fabs(d) > 1e-12 * scale * scale)) return std::nullopt;  // collinear
  const double a2 = a.x * a.x + a.y * a.y, b2 = b.x * b.x + b.y * b.y, c2 = c.x * c.x + c.y * c.y;
  const Point2 centre{(a2 * (b.y - c.y) + b2 * (c.y - a.y) + c2 * (a.y - b.y)) / d,
                      (a2 * (c.x - b.x) + b2 * (a.x - c.x) + c2 * (b.x - a.x)) / d};
  const bool ccw = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x) > 0;
  return Circle{centre, std::hypot(a.x - centre.x, a.y - centre.y), ccw};
}

// The angle swept from p_i to p_j round `circle` when points[i..j] fit it, or a negative value.
double fitted_sweep(const std::vector<Point2>& p, std::size_t i, std::size_t j, const Circle& k,
                    double tolerance) {
  const double dir = k.ccw ? 1 : -1;
  const double a0 = std::atan2(p[i].y - k.c.y, p[i].x - k.c.x);
  double swept = 0, prev_angle = a0, prev_error = 0;
  for (std::size_t m = i + 1; m <= j; ++m) {
    const double error = std::fabs(std::hypot(p[m].x - k.c.x, p[m].y - k.c.y) - k.r);
    const double a = std::atan2(p[m].y - k.c.y, p[m].x - k.c.x);
    double step = dir * (a - prev_angle);
    while (step < 0) step += 2 * M_PI;
    while (step >= 2 * M_PI) step -= 2 * M_PI;
    if (!(step > 0) || step > M_PI / 2) return -1;  // backwards, or a jump round the circle
    // The sub-arc lies within its sagitta of the chord between its ends on the circle, and that
    // chord within the larger radial error of the segment it replaces: both ways, so the sum bounds
    // the Hausdorff distance between the arc piece and the segment.
    const double sagitta = k.r * (1 - std::cos(step / 2));
    if (sagitta + std::max(error, prev_error) > tolerance) return -1;
    swept += step;
    if (swept >= M_PI) return -1;
    prev_angle = a, prev_error = error;
  }
  return swept;
}

}  // namespace

std::vector<PathMove> fit_arcs(const std::vector<Point2>& p, double tolerance, double max_radius) {
  std::vector<PathMove> out;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i + 1 < n;) {
    std::size_t best = i + 1;
    Circle best_circle{};
    double best_sweep = 0;
    for (std::size_t j = i + 2; j < n; ++j) {
      const auto k = circle_through(p[i], p[(i + j) / 2], p[j]);
      if (!k || k->r > max_radius) break;
      const double sweep = fitted_sweep(p, i, j, *k, tolerance);
      if (sweep < 0) break;
      best = j, best_circle = *k, best_sweep = sweep;
    }
    PathMove move;
    move.to = p[best];
    if (best >= i + 2) {
      move.arc = true;
      move.ccw = best_circle.ccw;
      move.center = best_circle.c;
      move.length = best_circle.r * best_sweep;
    } else {
      move.length = std::hypot(p[best].x - p[i].x, p[best].y - p[i].y);
    }
    out.push_back(move);
    i = best;
  }
  return out;
}

}  // namespace salient::core
