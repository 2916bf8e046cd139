// split_mesh: the two parts of a surface on either side of a vertical cut, each with its values
// (saliency) carried along, for profiling each part on its own (SegOpt, paper §5).
#pragma once

#include <array>
#include <span>
#include <vector>

#include "core/mesh/mesh.hpp"
#include "core/segment/cut_plane.hpp"

namespace salient::core {

struct MeshPart {
  Mesh mesh;                  // the part's faces only: no cap is added on the cut (it is inside)
  std::vector<float> values;  // one per vertex of `mesh`
  double area = 0;            // mm² of surface
};

// Faces crossing the plane are cut along it; new vertices interpolate position and value.
std::array<MeshPart, 2> split_mesh(const Mesh& mesh, std::span<const float> values, const CutPlane& plane);

// The part of the surface between heights z0 and z1 (a slab of a part, for recursive SegOpt).
MeshPart crop_z(const Mesh& mesh, std::span<const float> values, double z0, double z1);

}  // namespace salient::core
