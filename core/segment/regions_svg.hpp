// regions_svg: a multi-region plan drawn as each part's layers against height.
#pragma once

#include <string>
#include <vector>

#include "core/segment/plan_region.hpp"

namespace salient::core {

// Two columns, one per side of the cut, sharing the height axis; a whole-section region spans
// both (on a grey band). One bar per layer, its length the thickness (α..ᾱ), thin = red to
// thick = blue; dashed lines at the slab boundaries.
std::string regions_svg(const ZProfile& whole, const std::vector<PlanRegion>& regions,
                        const std::string& title);

}  // namespace salient::core
