// Fuzz target for broken geometry: the bytes become a triangle soup (open, self-intersecting,
// flat, degenerate — whatever they encode), which goes through repair, placement, toolpaths
// and G-code. It must end in G-code or an InputError, never a crash or a hang.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/common/input_error.hpp"
#include "core/gcode/gcode_writer.hpp"
#include "core/mesh/mesh_repair.hpp"
#include "core/mesh/placement.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/toolpath/toolpath_generator.hpp"

using namespace salient::core;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // 9 bytes a triangle: three corners of three coordinates in 0..255 (a 25.5 mm cube, 0.1 mm steps).
  Mesh m;
  // At most 300 triangles: a random soup of thousands has millions of self-intersections, and
  // polygon clipping is quadratic in those; real meshes do not look like that.
  for (std::size_t at = 0; at + 9 <= size && m.triangle_count() < 300; at += 9) {
    Triangle t{};
    for (int k = 0; k < 3; ++k) {
      t[k] = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back({data[at + 3 * k] * 0.1, data[at + 3 * k + 1] * 0.1, data[at + 3 * k + 2] * 0.1});
    }
    m.triangles.push_back(t);
  }
  try {
    repair_mesh(m);
    if (m.triangles.empty()) return 0;
    const PrinterProfile printer = *builtin_printer("generic-i3");
    PlacementOptions o;
    o.bed_center_x = printer.bed_center_x();
    o.bed_center_y = printer.bed_center_y();
    const Placement p = place_mesh(m, o);
    const double h = p.bounds.size().z;
    if (!(h > 0.1)) return 0;
    std::vector<double> z{0};
    const double steps[] = {0.1, 0.3, 0.2};
    for (int i = 0; z.back() < h - 1e-9; ++i) z.push_back(std::min(h, z.back() + steps[i % 3]));
    ToolpathSettings s;
    s.max_gap = 2.0;
    const auto layers = generate_toolpaths(m, z, s);
    write_gcode(layers, printer, {});
  } catch (const InputError&) {
  }
  return 0;
}
