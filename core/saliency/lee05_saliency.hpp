// Lee, Varshney & Jacobs 2005, "Mesh saliency" (ALGORITHMS.md §1, `lee05`).
#pragma once

#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

// One value in [0, 1] per vertex. Parallel over vertices (TBB); cancellable.
std::vector<float> lee05_saliency(const Mesh& mesh, const RunContext& run = {});

// The paper's non-linear normalisation: scale to [0, 1], then multiply by (M − m̄)², m̄ the mean
// of the local maxima (over 2-rings) other than the global one. Exposed for tests.
std::vector<double> suppress_non_maxima(const std::vector<double>& values, const Mesh& mesh);

}  // namespace salient::core
