// add_support: where the part overhangs, and the columns of support under it.
//
// Overhang. A wall at θ from vertical moves dz·tan θ over a height dz. A slab of the part overhangs
// where it lies further than dz·tan(angle) outside the part a FIXED height below (reference_depth
// under its mid-height, dz the true distance between the mid-heights) — not the layer below: at
// 0.1 mm a 65° wall moves 0.21 mm per layer, 0.07 mm more than a 55° one, a sliver that the old
// per-layer test then lost in the 0.6 mm XY gap, so thin layers (where adaptive plans put the
// salient, often overhanging, details) got no support at all. Where it is steep, the wall's whole
// footprint over that height is the overhang (overhang_of), so the overhangs of successive slabs
// join into the area under the wall whatever the layers.
//
// Columns. Walking the printed layers down, what overhangs above is carried down whole and stops
// only on the part itself; each layer prints what is carried minus the part beside it grown by
// xy_gap and minus the part less than z_gap above it. The gaps are applied to what is printed,
// never to what is carried, so they cannot eat the support of the layers below.
//
// Segmented plans: a printed layer merged from several regions holds only the regions whose layers
// end at its top, while a coarse region's layer fills several printed layers. So the part is given
// as slabs (every region's own layers), and "the part at a height" is every slab spanning it.
#include "core/toolpath/support_generator.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/geometry/polygon_simplify.hpp"
#include "core/toolpath/infill_pattern.hpp"

namespace salient::core {
namespace {

constexpr double eps = 1e-9;  // mm

// The islands of `area` at least min_area large (mm²), as rings.
Polygons drop_small(const std::vector<ExPolygon>& area, double min_area) {
  Polygons out;
  for (const ExPolygon& e : area) {
    double a = signed_area(e.contour);
    for (const Polygon& h : e.holes) a += signed_area(h);
    if (std::fabs(a) < min_area) continue;
    out.push_back(e.contour);
    out.insert(out.end(), e.holes.begin(), e.holes.end());
  }
  return out;
}

// The support carried down to a layer: every overhang above, stopped by the part.
//
// Cut by each section it passes and refilled by the overhangs above, it gathers the sections'
// vertices, slivers, and — where a wall lies near the support angle, its slabs steep on some
// layers and not on others — combs of slits a layer's wall movement wide: thousands of vertices,
// and every layer's booleans slow with them. So each cut drops slivers and simplifies within
// 0.1 mm (Douglas–Peucker keeps its own output, so this does not drift layer by layer), and when
// the vertices have grown by a quarter the slits are closed (grow, then shrink: the column never
// loses area, however often). Both stay far inside the support's own 0.6 mm gap to the part.
class Column {
 public:
  void add(const Polygons& overhang) { area_.insert(area_.end(), overhang.begin(), overhang.end()); }
  bool empty() const { return area_.empty(); }

  // What is carried on through the layer whose part is `solid`.
  const Polygons& cut(const Polygons& solid) {
    if (vertices() > closed_vertices_ + closed_vertices_ / 4 + 200) {
      area_ = offset(offset(area_, slit), -slit);
      closed_vertices_ = vertices();
    }
    Polygons kept;
    for (const Polygon& ring : difference_of(area_, solid))
      if (std::fabs(signed_area(ring)) >= sliver) kept.push_back(simplify_polygon(ring, tolerance));
    area_ = std::move(kept);
    return area_;
  }

 private:
  static constexpr double slit = 0.1, tolerance = 0.1, sliver = 0.05;  // mm, mm, mm²

  std::size_t vertices() const {
    std::size_t n = 0;
    for (const Polygon& ring : area_) n += ring.size();
    return n;
  }

  Polygons area_;
  std::size_t closed_vertices_ = 0;
};

double mid(const PartSlab& s) {
  return 0.5 * (s.z_bottom + s.z_top);
}

// The slabs by top, to find those spanning a height without a scan of them all.
class SlabIndex {
 public:
  explicit SlabIndex(const std::vector<PartSlab>& part) : part_(part), by_top_(part.size()) {
    std::iota(by_top_.begin(), by_top_.end(), std::size_t{0});
    std::sort(by_top_.begin(), by_top_.end(),
              [&](std::size_t a, std::size_t b) { return part[a].z_top < part[b].z_top; });
    for (const PartSlab& s : part) thickest_ = std::max(thickest_, s.z_top - s.z_bottom);
  }

  // Slabs spanning height z: z_bottom < z <= z_top.
  template <class F>
  void spanning(double z, F&& f) const {
    auto it = std::lower_bound(by_top_.begin(), by_top_.end(), z,
                               [&](std::size_t s, double h) { return part_[s].z_top < h; });
    for (; it != by_top_.end() && part_[*it].z_top < z + thickest_ + eps; ++it)
      if (part_[*it].z_bottom < z) f(part_[*it]);
  }

  // Slabs sharing more than a sliver of the heights lo..hi.
  template <class F>
  void overlapping(double lo, double hi, F&& f) const {
    auto it = std::upper_bound(by_top_.begin(), by_top_.end(), lo + eps,
                               [&](double h, std::size_t s) { return h < part_[s].z_top; });
    for (; it != by_top_.end() && part_[*it].z_top < hi + thickest_ + eps; ++it)
      if (part_[*it].z_bottom < hi - eps) f(part_[*it]);
  }

 private:
  const std::vector<PartSlab>& part_;
  std::vector<std::size_t> by_top_;
  double thickest_ = 0;
};

// The overhang of a slab over the part reference_depth below it (dz between their mid-heights):
// where the slab reaches further than dz·tan(angle) outside that part, the wall in between is
// steep; what the slab gains over the part near there (within dz·tan(angle)) is that wall's
// footprint, all of which needs support. The steep points alone are only the outer band of the
// footprint, as wide as dz·(tan θ − tan angle): bands of successive slabs would not join.
Polygons overhang_of(const PartSlab& slab, const SlabIndex& index, const SupportSettings& s) {
  if (slab.region.empty()) return {};
  const double slope = std::tan(s.angle * M_PI / 180);
  const double z = mid(slab) - std::max(s.reference_depth, slab.z_top - slab.z_bottom);
  if (z <= 0) return {};  // on the bed
  Polygons below, grown;
  double reach = 0;
  index.spanning(z, [&](const PartSlab& r) {
    const double d = (mid(slab) - mid(r)) * slope;
    const Polygons g = offset(r.region, d);
    below.insert(below.end(), r.region.begin(), r.region.end());
    grown.insert(grown.end(), g.begin(), g.end());
    reach = std::max(reach, d);
  });
  const Polygons steep = difference_of(slab.region, grown);
  if (steep.empty()) return {};
  return difference_of(intersection_of(slab.region, offset(steep, reach)), below);
}

void add_paths(const Polygons& area, const SupportSettings& s, LayerToolpaths& layer) {
  std::vector<ExtrusionPath> paths;
  for (const Polyline& line : rectilinear_infill(area, s.spacing, 0))
    if (line.size() >= 2) paths.push_back({line, false, s.line_width, ExtrusionRole::support});
  layer.paths.insert(layer.paths.begin(), paths.begin(), paths.end());  // printed before the part
}

}  // namespace

std::vector<PartSlab> part_slabs(const std::vector<LayerToolpaths>& layers) {
  std::vector<PartSlab> part;
  part.reserve(layers.size());
  for (const LayerToolpaths& l : layers) part.push_back({l.region, l.z_bottom, l.z_top});
  return part;
}

void add_support(std::vector<LayerToolpaths>& layers, const SupportSettings& s, const RunContext& run) {
  add_support(layers, part_slabs(layers), s, run);
}

void add_support(std::vector<LayerToolpaths>& layers, const std::vector<PartSlab>& part,
                 const SupportSettings& s, const RunContext& run) {
  const std::size_t n = layers.size(), m = part.size();
  if (n < 2 || m < 2) return;
  const SlabIndex index(part);
  // Each slab's overhang, and each printed layer's part and keep-out area, are independent.
  std::vector<Polygons> overhang(m), solid(n), keep_out(n);
  tbb::parallel_for(std::size_t{0}, m, [&](std::size_t j) {
    run.check();
    overhang[j] = overhang_of(part[j], index, s);
  });
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    run.check();
    const auto add = [](Polygons& to, const PartSlab& r) {
      to.insert(to.end(), r.region.begin(), r.region.end());
    };
    index.overlapping(layers[i].z_bottom, layers[i].z_top, [&](const PartSlab& r) { add(solid[i], r); });
    keep_out[i] = offset(solid[i], s.xy_gap);
    // The part within z_gap above: the air between support's top and the overhang.
    index.overlapping(layers[i].z_top, layers[i].z_top + s.z_gap,
                      [&](const PartSlab& r) { add(keep_out[i], r); });
  });
  // Top-down: a slab's overhang joins the column under it, which stops on the part (the plate
  // the overhang lies on, the bed).
  std::vector<std::size_t> by_bottom(m);
  std::iota(by_bottom.begin(), by_bottom.end(), std::size_t{0});
  std::sort(by_bottom.begin(), by_bottom.end(),
            [&](std::size_t a, std::size_t b) { return part[a].z_bottom > part[b].z_bottom; });
  std::vector<Polygons> carried(n);
  Column column;
  std::size_t next = 0;
  for (std::size_t i = n; i-- > 0;) {
    run.check();
    for (; next < m && part[by_bottom[next]].z_bottom >= layers[i].z_top - eps; ++next)
      column.add(overhang[by_bottom[next]]);
    if (!column.empty()) carried[i] = column.cut(solid[i]);
  }
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    run.check();
    if (carried[i].empty()) return;
    add_paths(drop_small(difference_ex(carried[i], keep_out[i]), s.min_area), s, layers[i]);
  });
}

}  // namespace salient::core
