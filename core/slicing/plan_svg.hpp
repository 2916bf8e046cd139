// An SVG of a plan: layer thickness against height (the paper's Fig. 2 as a plot), with the
// saliency profile S(z) beside it.
#pragma once

#include <string>

#include "core/slicing/objective.hpp"

namespace salient::core {

std::string plan_svg(const Objective& objective, const LayerPlan& plan, const std::string& title);

}  // namespace salient::core
