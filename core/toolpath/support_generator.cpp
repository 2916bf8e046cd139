// add_support. The overhang of layer j over layer j−1 is what of layer j lies further than
// h_j·tan(angle) outside layer j−1 — the distance a wall at that angle moves in one layer.
#include "core/toolpath/support_generator.hpp"

#include <cmath>

#include "core/toolpath/infill_pattern.hpp"

namespace salient::core {
namespace {

Polygons drop_small(const Polygons& polygons, double min_area) {
  Polygons out;
  for (const ExPolygon& e : union_ex(polygons)) {
    double area = signed_area(e.contour);
    for (const Polygon& h : e.holes) area += signed_area(h);
    if (std::fabs(area) < min_area) continue;
    out.push_back(e.contour);
    out.insert(out.end(), e.holes.begin(), e.holes.end());
  }
  return out;
}

}  // namespace

void add_support(std::vector<LayerToolpaths>& layers, const SupportSettings& s, const RunContext& run) {
  const std::size_t n = layers.size();
  if (n < 3) return;
  const double slope = std::tan(s.angle * M_PI / 180);
  auto overhang = [&](std::size_t j) {  // of layer j over layer j − 1
    return difference_of(layers[j].region, offset(layers[j - 1].region, layers[j].height() * slope));
  };
  Polygons carried;  // support area of the layer above
  for (std::size_t i = n - 2; i-- > 0;) {
    run.check();
    Polygons wanted = carried;
    const Polygons o = overhang(i + 2);
    wanted.insert(wanted.end(), o.begin(), o.end());
    if (wanted.empty()) continue;
    carried = drop_small(difference_of(union_of(wanted), offset(layers[i].region, s.xy_gap)), s.min_area);
    for (const Polyline& line : rectilinear_infill(carried, s.spacing, 0))
      if (line.size() >= 2)
        layers[i].paths.insert(layers[i].paths.begin(), {line, false, s.line_width, ExtrusionRole::support});
  }
}

}  // namespace salient::core
