// Planar regions: a mesh's faces grouped into connected pieces that lie on one plane (within a
// small angle and distance). A model's flat base is one; automatic orientation offers each large
// one, and each large facet of the model's convex hull, as a face to stand the model on.
#pragma once

#include <cstdint>
#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::core {

struct PlanarRegion {
  Vec3 normal;    // unit, outward: the area-weighted mean of its faces' normals
  Vec3 centroid;  // area-weighted, on the region
  double area = 0;
  std::vector<std::uint32_t> faces;  // indices into mesh.triangles
};

// Grown from the largest face down: a face joins a region through a shared edge when its normal is
// within `max_angle` (radians) of the region's and its corners within `max_distance` (the mesh's
// units) of the region's plane. Largest region first. Degenerate faces belong to none.
std::vector<PlanarRegion> planar_regions(const Mesh& mesh, double max_angle, double max_distance);

// Whether the point `p`, projected along the region's normal, falls inside one of its faces: a
// model whose centre of mass does so rests on that region without toppling.
bool projects_inside(const Mesh& mesh, const PlanarRegion& region, const Vec3& p);

}  // namespace salient::core
