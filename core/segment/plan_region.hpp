// PlanRegion: one part of a multi-region (segmented) plan — a horizontal slab of the model,
// either its whole section or one side of a vertical cut, with its own layers (paper §5).
#pragma once

#include <string>
#include <vector>

#include "core/geometry/polygon.hpp"
#include "core/slicing/layer_plan.hpp"
#include "core/slicing/z_profile.hpp"

namespace salient::core {

struct PlanRegion {
  int first_cell = 0, last_cell = 0;  // the slab [first, last) on the whole model's grid
  int side = -1;                      // -1: the whole section; 0 or 1: that side of the cut
  Polygon clip;                       // the XY area it prints (empty: all of it)
  LayerPlan plan;                     // boundaries in the whole model's cells, first..last
  double error = 0, epsilon = 0;      // E and ε = ρ·E(coarse), both on the region's own profile

  int layers() const { return plan.layer_count(); }
};

// Whether two regions print side by side: the two sides of the cut over a common height.
bool touching(const PlanRegion& a, const PlanRegion& b);

// Empty if `regions` are a valid plan for the model profiled by `whole`, else what is wrong:
// each region's layers lie within α..ᾱ and span its slab; every height is covered once by a
// whole-section region or once by each side; and where two regions touch, their printed heights
// are the same or at least α apart (a nozzle never prints a sliver of a layer against a seam) and
// so never further apart than ᾱ.
std::string check_regions(const ZProfile& whole, const std::vector<PlanRegion>& regions);

// Cells k of the region's slab (0-based from first_cell, one per boundary position) where a
// boundary keeps that rule against `neighbour`'s boundaries.
std::vector<char> seam_allowed(const ZProfile& whole, int first_cell, int last_cell, const PlanRegion& neighbour);

}  // namespace salient::core
