// generate_toolpaths. Skins: layer i's top skin is the part of its infill area not covered by
// every layer whose bottom lies less than top_thickness above layer i's top (all of it if the
// model ends within that distance); bottom skins alike downwards. With variable heights this is
// a distance in millimetres, not a count of layers.
// Spacing: a line of width w and height h has rounded sides, so neighbouring lines sit
// w − h·(1 − π/4) apart (Slic3r's flow model); each layer uses its own height, so thick and thin
// layers both fill their area exactly.
#include "core/toolpath/toolpath_generator.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/geometry/mesh_section.hpp"
#include "core/geometry/polygon_simplify.hpp"
#include "core/toolpath/infill_pattern.hpp"

namespace salient::core {
namespace {

void add_loops(const Polygons& rings, double width, ExtrusionRole role, LayerToolpaths& out) {
  for (const Polygon& ring : rings)
    if (ring.size() >= 3) out.paths.push_back({ring, true, width, role});
}

void add_lines(const Polylines& lines, double width, ExtrusionRole role, LayerToolpaths& out) {
  for (const Polyline& line : lines)
    if (line.size() >= 2) out.paths.push_back({line, false, width, role});
}

// Intersection of the regions of layers [first, last] (empty range: nothing covers).
Polygons covered_by(const std::vector<Polygons>& regions, std::size_t first, std::size_t last) {
  if (first > last || last >= regions.size()) return {};
  Polygons covered = regions[first];
  for (std::size_t j = first + 1; j <= last && !covered.empty(); ++j)
    covered = intersection_of(covered, regions[j]);
  return covered;
}

// PrusaSlicer's solid_infill_below_area (LayerRegion::prepare_fill_surfaces): each island of
// sparse infill, holes taken off, of at most that area becomes solid.
void fill_small_islands(const ToolpathSettings& s, Polygons& solid, Polygons& sparse) {
  if (!(s.solid_infill_below_area > 0) || !(s.infill_density > 0) || s.infill_density >= 1 || sparse.empty())
    return;
  std::vector<ExPolygon> small, kept;
  for (ExPolygon& island : union_ex(sparse)) {
    double area = std::abs(signed_area(island.contour));
    for (const Polygon& hole : island.holes) area -= std::abs(signed_area(hole));
    (area <= s.solid_infill_below_area ? small : kept).push_back(std::move(island));
  }
  if (small.empty()) return;
  const Polygons filled = to_polygons(small);
  solid.insert(solid.end(), filled.begin(), filled.end());
  solid = union_of(solid);
  sparse = to_polygons(kept);
}

void build_layer(std::size_t i, const std::vector<Polygons>& regions, const std::vector<double>& z,
                 const ToolpathSettings& s, std::vector<LayerToolpaths>& out) {
  const std::size_t n = out.size();
  const double w = s.line_width;
  LayerToolpaths& layer = out[i];
  if (i == 0 && s.skirt_distance > 0)
    add_loops(union_of(offset(regions[0], s.skirt_distance)), w, ExtrusionRole::skirt, layer);
  const double spacing = w - layer.height() * (1 - M_PI / 4);
  // Walls, outermost last (it is printed onto the inner ones' support).
  Polygons inner = regions[i];
  std::vector<Polygons> walls;
  for (int k = 0; k < s.walls && !inner.empty(); ++k) {
    const Polygons centre = offset(regions[i], -(0.5 * w + k * spacing));
    if (centre.empty()) break;
    walls.push_back(centre);
    inner = offset(regions[i], -(0.5 * w + (k + 0.5) * spacing));
  }
  for (std::size_t k = walls.size(); k-- > 0;)
    add_loops(walls[k], w, k == 0 ? ExtrusionRole::external_perimeter : ExtrusionRole::perimeter, layer);
  layer.wall_area = covered_area(regions[i]) - covered_area(inner);
  if (inner.empty()) return;
  // Skins: which layers lie within the skin thickness above and below?
  std::size_t up = i;
  while (up + 1 < n && out[up + 1].z_bottom < layer.z_top + s.top_thickness - 1e-9) ++up;
  std::size_t down = i;
  while (down > 0 && out[down - 1].z_top > layer.z_bottom - s.bottom_thickness + 1e-9) --down;
  const bool top_open = layer.z_top + s.top_thickness > z.back() + 1e-9 && up == n - 1;
  const bool bottom_open = layer.z_bottom - s.bottom_thickness < -1e-9 && down == 0;
  Polygons solid;
  if (top_open || bottom_open || up == i || down == i) {
    solid = inner;
  } else {
    const Polygons above = covered_by(regions, i + 1, up), below = covered_by(regions, down, i - 1);
    solid = union_of(difference_of(inner, above));
    const Polygons bottom_skin = difference_of(inner, below);
    solid.insert(solid.end(), bottom_skin.begin(), bottom_skin.end());
    solid = union_of(solid);
  }
  layer.sparse = difference_of(inner, solid);
  fill_small_islands(s, solid, layer.sparse);
  layer.solid_area = covered_area(solid);
  layer.sparse_area = covered_area(layer.sparse);
  const double angle = (i % 2 == 0 ? 45.0 : 135.0) * M_PI / 180;
  add_lines(rectilinear_infill(solid, spacing, angle), w, ExtrusionRole::solid_infill, layer);
}

// Sparse infill, in groups of consecutive layers no thicker together than combine_infill_up_to:
// where every layer of a group has sparse infill it is printed once, on the group's top layer,
// as thick as the group; elsewhere each layer prints its own. Rectilinear at 45°/135° by group,
// so the lines of successive groups cross.
void add_sparse_infill(std::vector<LayerToolpaths>& layers, const ToolpathSettings& s,
                       const RunContext& run) {
  if (!(s.infill_density > 0)) return;
  std::vector<std::pair<std::size_t, std::size_t>> groups;  // [first, last]
  for (std::size_t i = 0; i < layers.size();) {
    std::size_t j = i;
    double h = layers[i].height();
    while (j + 1 < layers.size() && h + layers[j + 1].height() <= s.combine_infill_up_to + 1e-9)
      h += layers[++j].height();
    groups.emplace_back(i, j);
    i = j + 1;
  }
  tbb::parallel_for(std::size_t{0}, groups.size(), [&](std::size_t g) {
    run.check();
    const auto [first, last] = groups[g];
    const double angle = (g % 2 == 0 ? 45.0 : 135.0) * M_PI / 180;
    const double w = s.line_width;
    Polygons common = layers[first].sparse;
    for (std::size_t k = first + 1; k <= last && !common.empty(); ++k)
      common = intersection_of(common, layers[k].sparse);
    if (first == last) common.clear();
    for (std::size_t k = first; k <= last; ++k) {
      LayerToolpaths& layer = layers[k];
      const Polygons own = common.empty() ? layer.sparse : difference_of(layer.sparse, common);
      const double spacing = w - layer.height() * (1 - M_PI / 4);
      add_lines(rectilinear_infill(own, spacing / s.infill_density, angle), w, ExtrusionRole::sparse_infill,
                layer);
    }
    if (common.empty()) return;
    LayerToolpaths& top = layers[last];
    const double h = top.z_top - layers[first].z_bottom;
    const std::size_t before = top.paths.size();
    add_lines(rectilinear_infill(common, (w - h * (1 - M_PI / 4)) / s.infill_density, angle), w,
              ExtrusionRole::sparse_infill, top);
    for (std::size_t p = before; p < top.paths.size(); ++p) top.paths[p].height = h;
  });
}

}  // namespace

namespace {

// A run of layers no taller than this whose sections were all open chains, between layers that
// have an outline, is filled from them. A taller run would be a guessed shape: refused later.
constexpr double max_filled_run = 1.0;  // mm

// As PrusaSlicer's fix_slicing_errors: a layer whose section is only open chains (a tear the
// chain closing could not bridge, e.g. where separate eyeballs cut a head's sockets) takes the
// outline common to the nearest good layers below and above, so the model above is not printed
// on air. Marks them `filled` for the result's warning.
void fill_open_layers(std::vector<Polygons>& regions, const std::vector<double>& z,
                      std::vector<LayerToolpaths>& out) {
  const auto bad = [&](std::size_t i) { return regions[i].empty() && out[i].open_chains > 0; };
  for (std::size_t i = 1; i < regions.size(); ++i) {
    if (!bad(i) || regions[i - 1].empty()) continue;
    std::size_t j = i;
    while (j < regions.size() && bad(j)) ++j;
    if (j == regions.size() || regions[j].empty() || z[j] - z[i] > max_filled_run + 1e-9) {
      i = j;
      continue;
    }
    const Polygons common = intersection_of(regions[i - 1], regions[j]);
    for (std::size_t k = i; k < j; ++k) {
      regions[k] = common;
      out[k].region = common;
      out[k].filled = !common.empty();
    }
    i = j;
  }
}

// Layers [first, last) of `z`'s layers are built; the others are context only (a region's slab
// inside the model: what lies above and below it decides where its skins go).
std::vector<LayerToolpaths> build_layers(const Mesh& mesh, const std::vector<double>& z, std::size_t first,
                                         std::size_t last, const ToolpathSettings& s, const RunContext& run) {
  const std::size_t n = z.size() < 2 ? 0 : z.size() - 1;
  std::vector<double> mid(n);
  for (std::size_t i = 0; i < n; ++i) mid[i] = 0.5 * (z[i] + z[i + 1]);
  SectionOptions so;
  so.max_gap = s.max_gap;
  const std::vector<Section> sections = section_mesh(mesh, mid, so, run);
  std::vector<Polygons> regions(n);  // the layer's solid area
  std::vector<LayerToolpaths> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Simplified before the walls are inset (not each wall after): one pass serves walls, skins
    // and infill outlines, and the offsets of a ring within `resolution` stay within it.
    const Polygons loops = simplify_polygons(sections[i].loops, s.resolution);
    regions[i] = s.clip.empty() ? union_of(loops) : intersection_of(union_of(loops), s.clip);
    out[i].region = regions[i];
    out[i].z_bottom = z[i];
    out[i].z_top = z[i + 1];
    out[i].open_chains = sections[i].open_chains;
  }
  fill_open_layers(regions, z, out);
  // Layers only read each other's regions: in parallel, in blocks so progress and cancellation
  // stay on the calling thread.
  constexpr std::size_t block = 64;
  for (std::size_t from = first; from < last; from += block) {
    run.check();
    run.report("toolpaths", static_cast<double>(from - first) / (last - first));
    tbb::parallel_for(from, std::min(last, from + block), [&](std::size_t i) {
      run.check();  // also inside a block: one layer of a pathological mesh can take long
      build_layer(i, regions, z, s, out);
    });
  }
  out.erase(out.begin() + static_cast<std::ptrdiff_t>(last), out.end());
  out.erase(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(first));
  add_sparse_infill(out, s, run);
  run.report("toolpaths", 1.0);
  return out;
}

}  // namespace

std::vector<LayerToolpaths> generate_toolpaths(const Mesh& mesh, const std::vector<double>& z,
                                               const ToolpathSettings& s, const RunContext& run) {
  return build_layers(mesh, z, 0, z.size() < 2 ? 0 : z.size() - 1, s, run);
}

std::vector<LayerToolpaths> generate_region_toolpaths(const Mesh& mesh, const std::vector<double>& z,
                                                      double model_height, const ToolpathSettings& s,
                                                      const RunContext& run) {
  if (z.size() < 2) return {};
  // Context layers as thick as the region's outermost ones, through the skin thickness (to the
  // bed and to the model's top at most).
  std::vector<double> below, above;
  const double h_low = z[1] - z[0], h_high = z.back() - z[z.size() - 2];
  for (double b = z.front(); b > 1e-9 && z.front() - b < s.bottom_thickness - 1e-9;)
    below.push_back(b = std::max(0.0, b - h_low));
  for (double t = z.back(); t < model_height - 1e-9 && t - z.back() < s.top_thickness - 1e-9;)
    above.push_back(t = std::min(model_height, t + h_high));
  std::vector<double> all(below.rbegin(), below.rend());
  all.insert(all.end(), z.begin(), z.end());
  all.insert(all.end(), above.begin(), above.end());
  ToolpathSettings own = s;
  own.skirt_distance = 0;  // one skirt round the merged first layer: add_skirt
  return build_layers(mesh, all, below.size(), below.size() + z.size() - 1, own, run);
}

std::vector<LayerToolpaths> merge_by_print_height(const std::vector<std::vector<LayerToolpaths>>& regions) {
  std::vector<const LayerToolpaths*> all;
  for (const auto& region : regions)
    for (const LayerToolpaths& layer : region)
      if (!layer.paths.empty()) all.push_back(&layer);  // a region's layer above its part of the model
  std::stable_sort(all.begin(), all.end(),
                   [](const LayerToolpaths* a, const LayerToolpaths* b) { return a->z_top < b->z_top; });
  std::vector<LayerToolpaths> out;
  constexpr double same = 1e-6;  // mm: tops closer than this are one printed layer
  for (const LayerToolpaths* layer : all) {
    if (out.empty() || layer->z_top > out.back().z_top + same) {
      LayerToolpaths merged;
      merged.z_top = layer->z_top;
      merged.z_bottom = out.empty() ? 0 : out.back().z_top;
      out.push_back(std::move(merged));
    }
    LayerToolpaths& target = out.back();
    for (ExtrusionPath path : layer->paths) {
      if (path.height <= 0) path.height = layer->height();  // keeps its region's own height
      target.paths.push_back(std::move(path));
    }
    target.region.insert(target.region.end(), layer->region.begin(), layer->region.end());
    target.wall_area += layer->wall_area;
    target.solid_area += layer->solid_area;
    target.sparse_area += layer->sparse_area;
    target.open_chains += layer->open_chains;
    target.filled = target.filled || layer->filled;
  }
  for (LayerToolpaths& layer : out) layer.region = union_of(layer.region);
  return out;
}

void add_skirt(std::vector<LayerToolpaths>& layers, const ToolpathSettings& s) {
  if (layers.empty() || !(s.skirt_distance > 0)) return;
  LayerToolpaths skirt;
  add_loops(union_of(offset(layers.front().region, s.skirt_distance)), s.line_width, ExtrusionRole::skirt,
            skirt);
  auto& paths = layers.front().paths;
  paths.insert(paths.begin(), skirt.paths.begin(), skirt.paths.end());
}

}  // namespace salient::core
