// Helpers for mesh tests: small meshes built in code, and paths of the shared models.
#pragma once

#include <string>

#include "core/mesh/mesh.hpp"

namespace salient::test {

inline std::string model_path(const std::string& name) { return std::string(SALIENT_MODELS_DIR) + "/" + name; }

// An axis-aligned box from (0,0,0) to (sx,sy,sz), outward-facing, 8 vertices, 12 triangles.
inline core::Mesh box(double sx = 1, double sy = 1, double sz = 1) {
  core::Mesh m;
  m.positions = {{0, 0, 0}, {sx, 0, 0}, {sx, sy, 0}, {0, sy, 0},
                 {0, 0, sz}, {sx, 0, sz}, {sx, sy, sz}, {0, sy, sz}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return m;
}

}  // namespace salient::test
