// Helpers for mesh tests: small meshes built in code, and paths of the shared models.
#pragma once

#include <cmath>
#include <string>

#include "core/mesh/mesh.hpp"

namespace salient::test {

inline std::string model_path(const std::string& name) {
  return std::string(SALIENT_MODELS_DIR) + "/" + name;
}

// An axis-aligned box from (0,0,0) to (sx,sy,sz), outward-facing, 8 vertices, 12 triangles.
inline core::Mesh box(double sx = 1, double sy = 1, double sz = 1) {
  core::Mesh m;
  m.positions = {{0, 0, 0},  {sx, 0, 0},  {sx, sy, 0},  {0, sy, 0},
                 {0, 0, sz}, {sx, 0, sz}, {sx, sy, sz}, {0, sy, sz}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return m;
}

// A unit UV sphere: poles at ±z, `rings` bands of latitude, `segments` of longitude.
inline core::Mesh uv_sphere(int rings, int segments) {
  core::Mesh m;
  m.positions.push_back({0, 0, -1});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double phi = M_PI * r / rings, theta = 2 * M_PI * s / segments;
      m.positions.push_back(
          {std::sin(phi) * std::cos(theta), std::sin(phi) * std::sin(theta), -std::cos(phi)});
    }
  m.positions.push_back({0, 0, 1});
  const auto ring = [&](int r, int s) {
    return static_cast<std::uint32_t>(1 + (r - 1) * segments + (s % segments));
  };
  const auto top = static_cast<std::uint32_t>(m.positions.size() - 1);
  for (int s = 0; s < segments; ++s) {
    m.triangles.push_back({0, ring(1, s + 1), ring(1, s)});
    m.triangles.push_back({top, ring(rings - 1, s), ring(rings - 1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.triangles.push_back({ring(r, s), ring(r, s + 1), ring(r + 1, s + 1)});
      m.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r + 1, s)});
    }
  }
  return m;
}

}  // namespace salient::test
