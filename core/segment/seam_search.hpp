// find_cut: the vertical cutting plane of least seam cost (paper §5, "Vertical Cutting Plane
// Optimization"): f(C) = ∫_C (Q + λ1·S) dC − λ2·D over planes sampled as directions × offsets.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"
#include "core/segment/cut_plane.hpp"

namespace salient::core {

struct SeamOptions {
  int directions = 90;     // plane normals spread over 180° in the XY plane (2° apart)
  int offsets = 50;        // positions along the model's extent in that direction (the paper's 50)
  double lambda1 = 0.3;    // weight of saliency on the seam
  double lambda2 = 0.4;    // weight of the parts' saliency difference
  double min_share = 0.1;  // least share of the surface area either part must have
};

struct SeamCandidate {
  CutPlane plane;
  double cost = 0;        // f(C)
  double seam_mean = 0;   // (1/|C|) ∫_C (Q + λ1·S) dC
  double difference = 0;  // D = |mean saliency of part 0 − of part 1| (area-weighted)
  double length = 0;      // |C|, mm
  double share = 0;       // the smaller part's share of the surface area
};

// Q is the signed mean curvature scaled by its 90th percentile magnitude and clamped to [−1, 1]
// (concave creases hide a seam: negative), S the saliency scaled to [0, 1]. The seam integral is
// taken as a mean over the seam so that f is dimensionless and λ1, λ2 keep their meaning whatever
// the model's size; parts under `min_share` of the surface are not considered (a sliver saves
// nothing). Directions in parallel. Empty if no plane divides the model.
std::optional<SeamCandidate> find_cut(const Mesh& mesh, std::span<const float> saliency,
                                      const SeamOptions& options = {}, const RunContext& run = {});

// The `count` best planes, least f(C) first, the best offset of each direction (so no two are
// near copies of each other).
std::vector<SeamCandidate> find_cuts(const Mesh& mesh, std::span<const float> saliency, int count,
                                     const SeamOptions& options = {}, const RunContext& run = {});

}  // namespace salient::core
