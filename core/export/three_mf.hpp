// 3MF export with PrusaSlicer's variable layer-height profile, so a PrusaSlicer user can keep
// their slicer and print our plan.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::core {

// The 3MF bytes: the mesh (mm) and, in Metadata/Slic3r_PE_layer_heights_profile.txt, the layer
// heights of `boundaries_z` (from 0 to the top) as PrusaSlicer's piecewise-linear profile.
std::string three_mf(const Mesh& mesh, const std::vector<double>& boundaries_z,
                     const std::string& object_name);

// The profile line alone: "object_id=1|z;h;z;h;…" (two points a layer: its bottom, and just
// under its top, so the profile is a step function).
std::string prusa_layer_height_profile(const std::vector<double>& boundaries_z);

void write_three_mf(const std::filesystem::path& path, const Mesh& mesh,
                    const std::vector<double>& boundaries_z, const std::string& object_name);

}  // namespace salient::core
