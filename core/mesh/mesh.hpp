// Mesh: an indexed triangle mesh with optional per-vertex colour and quality, and its measures.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/mesh/vec3.hpp"

namespace salient::core {

using Triangle = std::array<std::uint32_t, 3>;

// Linear RGB in [0, 1].
struct Color {
  float r = 0, g = 0, b = 0;
  bool operator==(const Color&) const = default;
};

struct BoundingBox {
  Vec3 min{}, max{};
  Vec3 size() const { return max - min; }
  Vec3 center() const { return (min + max) * 0.5; }
  double diagonal() const { return norm(size()); }
};

// Positions in millimetres once placed (the readers keep the file's units). `colors` and
// `quality` are either empty or have one entry per vertex. Triangles are counter-clockwise seen
// from outside once the mesh is repaired.
struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  std::vector<Color> colors;
  std::vector<float> quality;

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  bool has_colors() const { return !colors.empty(); }
  bool has_quality() const { return !quality.empty(); }
};

// Axis-aligned bounds of the vertices used by triangles (all vertices if there are none).
BoundingBox bounding_box(const Mesh& mesh);
// Total surface area, mm².
double surface_area(const Mesh& mesh);
// Signed enclosed volume (divergence theorem), mm³; positive for an outward-oriented closed mesh.
double signed_volume(const Mesh& mesh);
// Unnormalised normal (twice the area) and unit normal of triangle t; zero for degenerate ones.
Vec3 area_normal(const Mesh& mesh, std::size_t t);
Vec3 unit_normal(const Mesh& mesh, std::size_t t);
std::vector<Vec3> face_normals(const Mesh& mesh);

}  // namespace salient::core
