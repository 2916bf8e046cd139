// SegOpt wired to the slicer: the toolpaths of a multi-region plan (each region sliced at its own
// heights, merged by print height, paper §7) and the time estimate SegOpt decides by.
#pragma once

#include <vector>

#include "core/pipeline/planning_setup.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/segment/seg_opt.hpp"
#include "core/toolpath/support_generator.hpp"
#include "core/toolpath/toolpath_generator.hpp"

namespace salient::core {

struct RegionSliceSettings {
  ToolpathSettings toolpaths;
  bool support = false;
  SupportSettings support_settings;
};

// One region covering the whole model: the ordinary slice. Otherwise each region's layers cut to
// its side, merged by print height, one skirt, then support.
std::vector<LayerToolpaths> region_toolpaths(const Mesh& mesh, const ZProfile& whole,
                                             const std::vector<PlanRegion>& regions,
                                             const RegionSliceSettings& settings, const RunContext& run = {});

// Estimated seconds to print `regions` on `printer` (toolpaths and G-code, as slice would).
double region_print_seconds(const Mesh& mesh, const ZProfile& whole, const std::vector<PlanRegion>& regions,
                            const RegionSliceSettings& settings, const PrinterProfile& printer,
                            const RunContext& run = {});

// region_print_seconds of `setup`'s model, quietly (toolpath progress is not the caller's); stops
// when `run` is cancelled. `setup`, `settings` and `printer` must outlive it.
RegionTimer region_timer(const PlanningSetup& setup, const RegionSliceSettings& settings,
                         const PrinterProfile& printer, const RunContext& run = {});

// SegOpt on a prepared model with `planner` at the setup's ρ, timed on `printer`. Throws
// InputError for a planner that needs more than the objective (ha13 cuts the whole mesh).
SegOptResult segment_model(const PlanningSetup& setup, const Planner& planner,
                           const RegionSliceSettings& settings, const PrinterProfile& printer,
                           const RunContext& run = {}, SegOptOptions options = {});

// The printed heights (layer tops, mm) of a multi-region plan, merged.
std::vector<double> printed_heights(const ZProfile& whole, const std::vector<PlanRegion>& regions);

// E and RSMD of a multi-region plan: Σ of the regions' E, over Σ of their E(coarse) (= ε/ρ).
double regions_error(const std::vector<PlanRegion>& regions);

}  // namespace salient::core
