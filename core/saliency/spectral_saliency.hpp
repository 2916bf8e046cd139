// Song, Liu, Martin & Rosin 2014, "Mesh saliency via spectral processing" — the paper's
// saliency (ALGORITHMS.md §1, `spectral`).
#pragma once

#include <cstddef>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

struct SpectralOptions {
  std::size_t working_vertices = 1000;  // size of the simplified mesh the spectra are taken on
};

// One value in [0, 1] per vertex of `mesh`. The ten eigen-decompositions run in parallel (TBB).
std::vector<float> spectral_saliency(const Mesh& mesh, const SpectralOptions& options = {},
                                     const RunContext& run = {});

// Step 2–5 on one mesh: per-vertex saliency from the log-Laplacian spectrum's irregularity,
// back-projected over edges only. Exposed for tests.
std::vector<double> spectral_irregularity(const Mesh& mesh);

}  // namespace salient::core
