// WorkBounds: how much work a slice may ask for, checked on the placed model before saliency,
// so that settings inside their ranges (height 10000 at grid 0.001, scale 1e6) cannot take the
// memory of the machine, and a model too small for one layer never reaches the solvers.
#pragma once

#include <optional>

#include "core/mesh/mesh.hpp"
#include "core/pipeline/placed_model.hpp"

namespace salient::core {

// The printer's build volume, mm.
struct BuildVolume {
  double width = 0, depth = 0, height = 0;
};

// The most planning cells (model height / grid) a plan may have: 250 mm at the default grid
// 0.01 mm is 25,000; the exact planner's memory grows with cells × (max_layer / grid).
inline constexpr double kMaxPlanCells = 50000;

// Throws InputError naming the setting to change ({height}, {scale} or {grid}, else the model)
// when the placed model `placed` (mm) is thinner than {min_layer}, does not fit `volume` (when
// given), or would be cut into more than kMaxPlanCells cells of `grid` mm.
void check_work_bounds(const BoundingBox& placed, const MeshOptions& mesh, double min_layer, double grid,
                       const std::optional<BuildVolume>& volume);

}  // namespace salient::core
