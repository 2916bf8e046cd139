// GivenPlan: a plan made elsewhere (another slicer's layers, a plan file) put on our grid, so the
// objective scores it exactly as it scores our planners' plans.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/slicing/layer_plan.hpp"

namespace salient::core {

class ZProfile;

struct GivenPlan {
  LayerPlan plan;          // on the profile's grid
  int outside_limits = 0;  // layers thinner than α or thicker than ᾱ (scored all the same)
  double top = 0;          // the file's last layer top, mm, before it was set to the model's height
};

// Each top (mm, increasing) snapped to the nearest grid boundary; the last one becomes the model's
// top H when it lies within one thickest layer (ᾱ) of it — slicers end the last layer a little
// below or above H. Throws InputError naming `name` and the top's line (`lines`, 0: none) for tops
// that do not cover the model (ending more than ᾱ below H), that go more than ᾱ above it (a plan
// for another size or placement), or two tops in one grid cell (a finer grid is needed).
GivenPlan given_plan(const ZProfile& profile, const std::vector<double>& tops,
                     const std::vector<std::uint64_t>& lines, const std::string& name);

}  // namespace salient::core
