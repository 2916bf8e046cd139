// An SVG of a plan: layer thickness against height (the paper's Fig. 2 as a plot), with the
// saliency profile S(z) beside it.
#pragma once

#include <string>

#include "core/slicing/objective.hpp"

namespace salient::core {

// `caption`: a line under the title (the estimated minutes against the uniform baselines).
std::string plan_svg(const Objective& objective, const LayerPlan& plan, const std::string& title,
                     const std::string& caption = {});

}  // namespace salient::core
