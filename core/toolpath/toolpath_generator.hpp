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

// The layers `z` (boundaries, mm) of one region of a segmented plan: a slab of the model between
// z.front() and z.back(), cut to settings.clip. What the model has above and below the slab (up to
// `model_height`) decides where the region's skins go, as if it were sliced whole.
std::vector<LayerToolpaths> generate_region_toolpaths(const Mesh& mesh, const std::vector<double>& z,
                                                      double model_height, const ToolpathSettings& settings,
                                                      const RunContext& run = {});

// Multi-region plans (paper §5 and §7): each region is sliced with its own layers; the layers
// of all regions are merged by print height — one printed layer per distinct top z, holding
// every region's paths that end there, each keeping its own height (so its own extrusion).
// The printed layer's height is the rise from the previous printed top.
std::vector<LayerToolpaths> merge_by_print_height(const std::vector<std::vector<LayerToolpaths>>& regions);

// The skirt round the first layer's outline, printed first (for merged multi-region layers).
void add_skirt(std::vector<LayerToolpaths>& layers, const ToolpathSettings& settings);

}  // namespace salient::core
