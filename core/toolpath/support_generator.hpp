// Simple support under overhangs (ALGORITHMS.md §6): columns of sparse lines from the bed (or the
// part below) up to just under any part of the model that overhangs by more than a set angle.
#pragma once

#include <vector>

#include "core/common/progress.hpp"
#include "core/toolpath/toolpath.hpp"

namespace salient::core {

struct SupportSettings {
  double angle = 55;  // degrees from vertical: steeper overhangs get support
  // mm: each slab of the part is compared with the part this far below its mid-height (or one
  // layer, if thicker) — a fixed height, not a layer count, so thin layers see the same overhang.
  double reference_depth = 0.4;
  double xy_gap = 0.6;   // mm kept between support and the part printed beside it
  double z_gap = 0.1;    // mm at least between support's top and the overhang's bottom
  double spacing = 2.0;  // mm between support lines
  double line_width = 0.45;
  double min_area = 1.0;  // mm²: smaller islands of printed support are dropped
};

// A slab of the part as printed: its section (the region of a layer of one region of the plan)
// and the heights it fills, mm.
struct PartSlab {
  Polygons region;
  double z_bottom = 0, z_top = 0;
};

// Adds support paths (role support) to the printed `layers`, whose `region`s must be set: the part
// is the layers themselves (one plan for the whole model).
void add_support(std::vector<LayerToolpaths>& layers, const SupportSettings& settings,
                 const RunContext& run = {});

// The same for printed layers merged from several regions' layers (merge_by_print_height), where
// a printed layer holds only the regions whose layers end at its top: `part` is every region's
// layers, so a coarse layer spanning several printed layers is part of each of them.
void add_support(std::vector<LayerToolpaths>& layers, const std::vector<PartSlab>& part,
                 const SupportSettings& settings, const RunContext& run = {});

// The slabs of `layers` (their regions and heights), for the call above.
std::vector<PartSlab> part_slabs(const std::vector<LayerToolpaths>& layers);

}  // namespace salient::core
