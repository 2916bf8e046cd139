// PlanRegion: one part of a multi-region (segmented) plan — a horizontal slab of the model,
// either its whole section or one part of it cut by vertical planes, with its own layers (paper §5).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.hpp"
#include "core/geometry/polygon.hpp"
#include "core/slicing/layer_plan.hpp"
#include "core/slicing/z_profile.hpp"

namespace salient::core {

struct SegOptInput;  // core/segment/seg_opt.hpp: the planner, metric, ρ and seed plan_region uses

struct PlanRegion {
  int first_cell = 0, last_cell = 0;  // the slab [first, last) on the whole model's grid
  int side = -1;                      // -1: the whole section; 0 or 1: that side of the first cut
  std::vector<int> sub;           // the sides it lies on of deeper cuts inside that part (recursive SegOpt)
  Polygon clip;                   // the XY area it prints (empty: all of it)
  LayerPlan plan;                 // boundaries in the whole model's cells, first..last
  double error = 0, epsilon = 0;  // E and its budget ε, both on the region's own profile

  int layers() const { return plan.layer_count(); }
};

// Whether two regions print side by side: two different parts over a common height whose areas
// share a piece of border.
bool touching(const PlanRegion& a, const PlanRegion& b);

// Empty if `regions` are a valid plan for the model profiled by `whole`, else what is wrong:
// each region's layers lie within α..ᾱ and span its slab; every height is covered once by a
// whole-section region or by parts that tile the section (each cut's two sides, all the way
// down); and where two regions touch, their printed heights are the same or at least α apart (a
// nozzle never prints a sliver of a layer against a seam) and so never further apart than ᾱ.
std::string check_regions(const ZProfile& whole, const std::vector<PlanRegion>& regions);

// Cells k of [first_cell, last_cell] (0-based from first_cell, one per boundary position) where a
// boundary keeps that rule against every region in `neighbours`.
std::vector<char> seam_allowed(const ZProfile& whole, int first_cell, int last_cell,
                               const std::vector<const PlanRegion*>& neighbours);

// Plans the region `shape` (its slab, side and clip; its plan is made here) on `profile` with the
// input's planner to `epsilon` (by default ρ·E(coarse) of the slab); its boundaries also keep the
// seam rule against every region of `meet` it touches (the exact planner on the allowed cells when
// the planner's own plan breaks it). With `align`, it keeps to those regions' boundaries where that
// reaches ε. A region on the bed (first_cell 0) starts with the input's fixed first layer. Empty if
// no plan on the allowed cells reaches ε.
std::optional<PlanRegion> plan_region(const ZProfile& profile, PlanRegion shape,
                                      std::optional<double> epsilon, const SegOptInput& input,
                                      const std::vector<const PlanRegion*>& meet, const RunContext& run,
                                      const std::vector<const PlanRegion*>& align = {});

}  // namespace salient::core
