// SurfaceLocator: the closest point of a triangle mesh to a query, as a face and barycentric
// coordinates (an AABB tree, through CGAL).
#pragma once

#include <array>
#include <memory>
#include <span>

#include "core/mesh/mesh.hpp"

namespace salient::core {

struct SurfacePoint {
  std::uint32_t face = 0;
  std::array<double, 3> barycentric{1, 0, 0};  // weights of the face's three vertices
};

class SurfaceLocator {
 public:
  explicit SurfaceLocator(const Mesh& mesh);  // `mesh` must outlive the locator
  ~SurfaceLocator();
  SurfaceLocator(const SurfaceLocator&) = delete;
  SurfaceLocator& operator=(const SurfaceLocator&) = delete;

  SurfacePoint closest(const Vec3& query) const;

 private:
  struct Tree;
  const Mesh& mesh_;
  std::unique_ptr<Tree> tree_;
};

// Interpolates per-vertex `values` of `from` at the closest surface point of each vertex of `to`.
std::vector<double> transfer_values(const Mesh& from, std::span<const double> values, const Mesh& to);

}  // namespace salient::core
