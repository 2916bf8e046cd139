// generate_toolpaths: from a placed mesh and its layer boundaries to extrusion paths per layer
// (ALGORITHMS.md §6).
#pragma once

#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"
#include "core/toolpath/toolpath.hpp"

namespace salient::core {

// `boundaries_z` are the layer boundaries in mm, from 0 to the model's height. Each layer is
// cut at its mid-height; walls are inset from the section, the rest is solid where a top or
// bottom surface is nearer than the skin thickness (in mm, over however many layers that is),
// sparse elsewhere. Sections are one sweep; layers are then built in parallel (TBB).
std::vector<LayerToolpaths> generate_toolpaths(const Mesh& mesh, const std::vector<double>& boundaries_z,
                                               const ToolpathSettings& settings, const RunContext& run = {});

// Multi-region plans (paper §5 and §7): each region is sliced with its own layers; the layers
// of all regions are merged by print height — one printed layer per distinct top z, holding
// every region's paths that end there, each keeping its own height (so its own extrusion).
// The printed layer's height is the rise from the previous printed top.
std::vector<LayerToolpaths> merge_by_print_height(const std::vector<std::vector<LayerToolpaths>>& regions);

}  // namespace salient::core
