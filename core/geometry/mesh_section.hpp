// Mesh–plane sections: the closed contours where horizontal planes cut a mesh, chained by mesh
// edge so the topology is exact (ALGORITHMS.md §6).
#pragma once

#include <span>
#include <vector>

#include "core/common/progress.hpp"
#include "core/geometry/polygon.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

struct Section {
  Polygons loops;               // outer rings CCW, holes CW (for an outward-oriented mesh)
  std::size_t gaps_closed = 0;  // open chains closed because their ends were within max_gap
  std::size_t open_chains = 0;  // open chains left out (the mesh has a hole there)
};

struct SectionOptions {
  double max_gap = 1.0;  // mm: an open chain whose ends are closer than this is closed
};

// Sections of an indexed (welded) mesh at each of `heights`, in the order given. One sweep over
// the faces sorted by their lowest z; each plane visits only the faces spanning it. A vertex
// exactly on a plane counts as above it, so every crossing face has two crossing edges.
std::vector<Section> section_mesh(const Mesh& mesh, std::span<const double> heights,
                                  const SectionOptions& options = {}, const RunContext& run = {});

}  // namespace salient::core
