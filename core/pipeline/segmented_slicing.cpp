#include "core/pipeline/segmented_slicing.hpp"

#include <algorithm>
#include <cmath>

#include "core/common/input_error.hpp"
#include "core/gcode/gcode_writer.hpp"

namespace salient::core {
namespace {

std::vector<double> heights_of(const ZProfile& whole, const PlanRegion& region) {
  std::vector<double> z;
  for (int b : region.plan.boundaries) z.push_back(whole.z(b));
  return z;
}

}  // namespace

std::vector<LayerToolpaths> region_toolpaths(const Mesh& mesh, const ZProfile& whole,
                                             const std::vector<PlanRegion>& regions,
                                             const RegionSliceSettings& s, const RunContext& run) {
  std::vector<LayerToolpaths> layers;
  std::vector<PartSlab> part;  // with several regions: each one's own layers, for support
  if (regions.size() == 1 && regions[0].side < 0 && regions[0].first_cell == 0) {
    layers = generate_toolpaths(mesh, heights_of(whole, regions[0]), s.toolpaths, run);
  } else {
    std::vector<std::vector<LayerToolpaths>> each;
    for (const PlanRegion& region : regions) {
      ToolpathSettings own = s.toolpaths;
      if (!region.clip.empty()) own.clip = {region.clip};
      each.push_back(generate_region_toolpaths(mesh, heights_of(whole, region), whole.height(), own, run));
      if (s.support) {
        const std::vector<PartSlab> own_part = part_slabs(each.back());
        part.insert(part.end(), own_part.begin(), own_part.end());
      }
    }
    layers = merge_by_print_height(each);
    add_skirt(layers, s.toolpaths);
  }
  if (s.support) {
    SupportSettings support = s.support_settings;
    support.line_width = s.toolpaths.line_width;
    if (part.empty())
      add_support(layers, support, run);
    else
      add_support(layers, part, support, run);
  }
  return layers;
}

double region_print_seconds(const Mesh& mesh, const ZProfile& whole, const std::vector<PlanRegion>& regions,
                            const RegionSliceSettings& s, const PrinterProfile& printer,
                            const RunContext& run) {
  GcodeSettings gs;
  gs.cancel = run.cancel;
  return write_gcode(region_toolpaths(mesh, whole, regions, s, run), printer, gs).seconds;
}

RegionTimer region_timer(const PlanningSetup& setup, const RegionSliceSettings& settings,
                         const PrinterProfile& printer, const RunContext& run) {
  const RunContext quiet{run.cancel, {}};
  return [&setup, &settings, &printer, quiet](const std::vector<PlanRegion>& regions) {
    return region_print_seconds(setup.model.loaded.mesh, *setup.profile, regions, settings, printer, quiet);
  };
}

SegOptResult segment_model(const PlanningSetup& setup, const Planner& planner,
                           const RegionSliceSettings& settings, const PrinterProfile& printer,
                           const RunContext& run, SegOptOptions options) {
  if (planner.name() == to_string(PlannerKind::ha13))
    throw InputError(SettingId::planner,
                     "ha13 cuts the whole model's sections, so it cannot plan the parts of {segment}");
  const Mesh& mesh = setup.model.loaded.mesh;
  const SegOptInput input{mesh,    setup.saliency,   *setup.profile, setup.objective->metric(),
                          planner, setup.rho,        setup.seed,     nullptr,
                          {},      setup.first_cells};
  return seg_opt(input, region_timer(setup, settings, printer, run), options, run);
}

std::vector<double> printed_heights(const ZProfile& whole, const std::vector<PlanRegion>& regions) {
  std::vector<double> z;
  for (const PlanRegion& r : regions)
    for (std::size_t i = 1; i < r.plan.boundaries.size(); ++i) z.push_back(whole.z(r.plan.boundaries[i]));
  std::sort(z.begin(), z.end());
  z.erase(std::unique(z.begin(), z.end(), [](double a, double b) { return std::fabs(a - b) < 1e-6; }),
          z.end());
  return z;
}

double regions_error(const std::vector<PlanRegion>& regions) {
  double e = 0;
  for (const PlanRegion& r : regions) e += r.error;
  return e;
}

}  // namespace salient::core
