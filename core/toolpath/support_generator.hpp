// Simple support under overhangs (ALGORITHMS.md §6): columns of sparse lines from the bed up to
// one layer under any part of a layer that overhangs the one below by more than a set angle.
#pragma once

#include <vector>

#include "core/common/progress.hpp"
#include "core/toolpath/toolpath.hpp"

namespace salient::core {

struct SupportSettings {
  double angle = 55;     // degrees from vertical: steeper overhangs get support
  double xy_gap = 0.6;   // mm kept between support and the part
  double spacing = 2.0;  // mm between support lines
  double line_width = 0.45;
  double min_area = 1.0;  // mm²: smaller islands of support are dropped
};

// Adds support paths (role support) to `layers`, whose `region`s must be set. Layers are walked
// top-down: what layer i+2 overhangs, and what was supported above, is supported on layer i
// (one layer's gap under the overhang), minus the part itself grown by xy_gap.
void add_support(std::vector<LayerToolpaths>& layers, const SupportSettings& settings,
                 const RunContext& run = {});

}  // namespace salient::core
