// LayerTimeModel. The pre-pass cuts every face at the mid-plane of each cell it spans: the
// segment's length adds to the section's perimeter, and with the segment oriented so that the
// face's outward normal is on its right (a counter-clockwise outer contour seen from above) its
// shoelace term adds to the section's signed area — holes subtract, with no contour chaining.
#include "core/slicing/layer_time_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace salient::core {

struct LayerTimeModel::Sections {
  std::vector<double> perimeter, area;         // at each cell's mid-plane, mm and mm²
  std::vector<double> up_prefix, down_prefix;  // Σ of the projected area of up-/down-facing surface
};

namespace {

// Fraction of a face's area below height h, its vertex heights sorted z0 ≤ z1 ≤ z2 (as z_profile).
double area_below(const double z[3], double h) {
  if (h <= z[0]) return 0;
  if (h >= z[2]) return 1;
  const double span = z[2] - z[0];
  if (h <= z[1]) return (h - z[0]) * (h - z[0]) / (span * (z[1] - z[0]));
  return 1 - (z[2] - h) * (z[2] - h) / (span * (z[2] - z[1]));
}

Vec3 on_edge(const Vec3& a, const Vec3& b, double h) {
  const double t = (h - a.z) / (b.z - a.z);
  return a + (b - a) * t;
}

}  // namespace

LayerTimeModel::LayerTimeModel(const Mesh& mesh, const ZProfile& profile, const TimeModelParams& params)
    : params_(params), grid_(profile.grid()), height_(profile.height()), first_(0), last_(profile.cells()) {
  const int m = profile.cells();
  auto s = std::make_shared<Sections>();
  s->perimeter.assign(m, 0);
  s->area.assign(m, 0);
  std::vector<double> up(m, 0), down(m, 0);
  const double d = grid_;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    std::array<Vec3, 3> v{mesh.positions[mesh.triangles[t][0]], mesh.positions[mesh.triangles[t][1]],
                          mesh.positions[mesh.triangles[t][2]]};
    const Vec3 n = area_normal(mesh, t);
    if (!(is_finite(v[0]) && is_finite(v[1]) && is_finite(v[2]) && is_finite(n))) continue;
    std::sort(v.begin(), v.end(), [](const Vec3& a, const Vec3& b) { return a.z < b.z; });
    const double z[3] = {v[0].z, v[1].z, v[2].z};
    // Sections at the mid-planes of the cells the face crosses.
    const int k_lo = std::max(0, static_cast<int>(std::ceil(z[0] / d - 0.5)));
    const int k_hi = std::min(m - 1, static_cast<int>(std::floor(z[2] / d - 0.5)));
    for (int k = k_lo; k <= k_hi; ++k) {
      const double h = (k + 0.5) * d;
      if (!(h > z[0] && h < z[2])) continue;
      Vec3 p = on_edge(v[0], v[2], h);
      Vec3 q = h < z[1] ? on_edge(v[0], v[1], h) : on_edge(v[1], v[2], h);
      if (n.x * (q.y - p.y) - n.y * (q.x - p.x) < 0) std::swap(p, q);
      s->perimeter[k] += std::hypot(q.x - p.x, q.y - p.y);
      s->area[k] += 0.5 * (p.x * q.y - q.x * p.y);
    }
    // The horizontal projection of the face, spread over its cells as its area is.
    const double projected = 0.5 * std::fabs(n.z);
    if (!(projected > 0)) continue;
    std::vector<double>& into = n.z > 0 ? up : down;
    const int c_lo = std::clamp(static_cast<int>(std::floor(z[0] / d)), 0, m - 1);
    const int c_hi = std::clamp(static_cast<int>(std::floor(z[2] / d)), 0, m - 1);
    if (c_lo == c_hi || !(z[2] > z[0])) {
      into[c_lo] += projected;
      continue;
    }
    for (int c = c_lo; c <= c_hi; ++c)
      into[c] += projected * (area_below(z, (c + 1) * d) - area_below(z, c * d));
  }
  for (double& a : s->area) a = std::max(0.0, a);
  s->up_prefix.assign(m + 1, 0);
  s->down_prefix.assign(m + 1, 0);
  for (int k = 0; k < m; ++k) {
    s->up_prefix[k + 1] = s->up_prefix[k] + up[k];
    s->down_prefix[k + 1] = s->down_prefix[k] + down[k];
  }
  sections_ = std::move(s);
}

LayerTimeModel LayerTimeModel::window(int first, int last) const {
  LayerTimeModel w = *this;
  w.first_ = first_ + first;
  w.last_ = first_ + last;
  return w;
}

LayerFeatures LayerTimeModel::features(int i, int j) const {
  const Sections& s = *sections_;
  const TimeModelParams& p = params_;
  const int m = static_cast<int>(s.area.size());
  const int a = first_ + i, b = first_ + j;
  const double zb = a * grid_, zt = b >= m ? height_ : b * grid_, h = zt - zb;
  const int mid = std::clamp((a + b) / 2, 0, m - 1);
  const double spacing = p.line_width - h * (1 - M_PI / 4);
  LayerFeatures f;
  f.first = a == 0;
  const double perimeter = s.perimeter[mid];
  f.section_area = s.area[mid];
  f.wall_length = p.walls * perimeter;
  const double inner = std::max(0.0, s.area[mid] - p.walls * spacing * perimeter);
  double skin = inner;
  if (zt + p.top_thickness <= height_ + 1e-9 && zb - p.bottom_thickness >= -1e-9) {
    const auto cell = [&](double z) { return std::clamp(static_cast<int>(std::floor(z / grid_)), 0, m); };
    const double above = s.up_prefix[cell(zt + p.top_thickness)] - s.up_prefix[mid];
    const double below = s.down_prefix[mid] - s.down_prefix[cell(zb - p.bottom_thickness)];
    skin = std::min(inner, above + below);
  }
  const double sparse = inner - skin;
  f.solid_length = skin / spacing;
  f.infill_lines = skin > 0 ? std::sqrt(skin) / spacing : 0;
  if (p.infill_density > 0 && sparse > 0) {
    // Combined infill: groups of ⌊ᾱ/h⌋ layers share one pass, as thick as the group.
    const double group =
        p.combine_infill_up_to > 0 ? std::max(1.0, std::floor(p.combine_infill_up_to / h + 1e-9)) : 1.0;
    const double line_spacing = (p.line_width - group * h * (1 - M_PI / 4)) / p.infill_density;
    f.sparse_length = sparse / line_spacing / group;
    f.combined = group > 1;
    f.infill_lines += std::sqrt(sparse) / line_spacing / group;
  }
  return f;
}

double LayerTimeModel::layer_seconds(int i, int j) const {
  const TimeModelParams& p = params_;
  const LayerFeatures f = features(i, j);
  double speed = f.first ? p.first_layer_speed : p.print_speed;
  // The G-code writer's minimum layer time slows a quick layer's extrusion in proportion.
  const double nominal = (f.wall_length + f.solid_length + f.sparse_length) / speed;
  if (nominal > 0 && nominal < p.min_layer_time)
    speed = std::max(speed * nominal / p.min_layer_time, std::min(speed, p.min_print_speed));
  const double weighted =
      p.wall_factor * f.wall_length + p.solid_factor * f.solid_length + p.sparse_factor * f.sparse_length;
  const double travel = (p.travel_factor + (f.combined ? p.combined_travel_factor : 0)) *
                        std::sqrt(f.section_area) / p.travel_speed;
  return p.layer_overhead + weighted / speed + p.line_overhead * f.infill_lines + travel;
}

double LayerTimeModel::seconds(const LayerPlan& plan) const {
  double total = 0;
  for (int l = 0; l < plan.layer_count(); ++l)
    total += layer_seconds(plan.boundaries[l], plan.boundaries[l + 1]);
  return total;
}

}  // namespace salient::core
