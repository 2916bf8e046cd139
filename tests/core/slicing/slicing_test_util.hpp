// Helpers for slicing tests: shapes with known profiles and random small models.
#pragma once

#include <cmath>
#include <random>

#include "core/mesh/mesh.hpp"
#include "core/mesh/mesh_repair.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

namespace salient::test {

// A square pyramid with base side `s` on z = 0 and apex at height h (outward oriented).
inline core::Mesh pyramid(double s, double h) {
  core::Mesh m;
  m.positions = {{0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0}, {s / 2, s / 2, h}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  return m;
}

// A closed star-shaped blob: a UV sphere whose radius varies randomly per vertex, stood on
// z = 0. Random enough to give irregular profiles, always a valid closed mesh.
inline core::Mesh random_blob(std::mt19937& rng, int rings, int segments, double height) {
  std::uniform_real_distribution<double> radius(0.6, 1.4);
  core::Mesh m = uv_sphere(rings, segments);
  for (auto& p : m.positions) p = p * radius(rng);
  core::repair_mesh(m);
  double zmin = 1e9, zmax = -1e9;
  for (const auto& p : m.positions) zmin = std::min(zmin, p.z), zmax = std::max(zmax, p.z);
  for (auto& p : m.positions) p = core::Vec3{p.x, p.y, (p.z - zmin) / (zmax - zmin) * height};
  return m;
}

inline std::vector<float> random_saliency(std::mt19937& rng, std::size_t n) {
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> s(n);
  for (float& x : s) x = u(rng);
  return s;
}

}  // namespace salient::test
