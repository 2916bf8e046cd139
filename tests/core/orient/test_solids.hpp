// Closed solids built in code for the orientation tests: parts with a flat base (a bolt, a bust,
// a bullet), and an arbitrary turn that takes the base off the axes.
#pragma once

#include <cmath>
#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::test {

// Rotation about `axis` by `angle` (Rodrigues).
inline core::Vec3 rotate(const core::Vec3& p, const core::Vec3& axis, double angle) {
  const core::Vec3 k = axis / core::norm(axis);
  return p * std::cos(angle) + core::cross(k, p) * std::sin(angle) +
         k * (core::dot(k, p) * (1 - std::cos(angle)));
}

// A closed solid from rings of equally many points, bottom to top, each counter-clockwise seen from
// above; the bottom and top rings are closed by fans around their centres. Outward-facing.
inline core::Mesh ring_stack(const std::vector<std::vector<core::Vec3>>& rings) {
  core::Mesh m;
  const auto n = static_cast<std::uint32_t>(rings.front().size());
  for (const auto& ring : rings) m.positions.insert(m.positions.end(), ring.begin(), ring.end());
  const auto at = [&](std::size_t r, std::uint32_t j) { return static_cast<std::uint32_t>(r * n + j % n); };
  for (std::size_t r = 0; r + 1 < rings.size(); ++r)
    for (std::uint32_t j = 0; j < n; ++j) {
      m.triangles.push_back({at(r, j), at(r, j + 1), at(r + 1, j + 1)});
      m.triangles.push_back({at(r, j), at(r + 1, j + 1), at(r + 1, j)});
    }
  for (const std::size_t r : {std::size_t{0}, rings.size() - 1}) {
    core::Vec3 c{};
    for (const core::Vec3& p : rings[r]) c += p;
    m.positions.push_back(c / n);
    const auto centre = static_cast<std::uint32_t>(m.positions.size() - 1);
    for (std::uint32_t j = 0; j < n; ++j)
      m.triangles.push_back(r == 0 ? core::Triangle{centre, at(r, j + 1), at(r, j)}
                                   : core::Triangle{centre, at(r, j), at(r, j + 1)});
  }
  return m;
}

// `n` points around (cx, cy) at height z, radius `radius(θ)`.
template <typename Radius>
std::vector<core::Vec3> ring(int n, double cx, double cy, double z, Radius&& radius) {
  std::vector<core::Vec3> out;
  for (int j = 0; j < n; ++j) {
    const double t = 2 * M_PI * j / n;
    out.push_back({cx + radius(t) * std::cos(t), cy + radius(t) * std::sin(t), z});
  }
  return out;
}

// A bolt standing on its head: a hexagonal head (across corners 2·head, `head_height` tall) and a
// round shank (radius `shank`, `length` long) on it.
inline core::Mesh bolt(double head = 12, double head_height = 8, double shank = 5, double length = 36) {
  const int n = 48;  // a multiple of 6: the hexagon's corners are ring points
  const auto hex = [&](double t) {
    const double sector = std::fmod(t, M_PI / 3) - M_PI / 6;
    return head * std::cos(M_PI / 6) / std::cos(sector);
  };
  const auto round = [&](double) { return shank; };
  return ring_stack({ring(n, 0, 0, 0, hex), ring(n, 0, 0, head_height, hex),
                     ring(n, 0, 0, head_height, round), ring(n, 0, 0, head_height + length, round)});
}

// A bust on a round pedestal (radius 16, 5 mm tall): a neck, then a head leaning forward (+x) and
// longer than wide, rounded on top; 45 mm tall in all.
inline core::Mesh bust() {
  const int n = 48;
  std::vector<std::vector<core::Vec3>> rings;
  rings.push_back(ring(n, 0, 0, 0, [](double) { return 16.0; }));
  rings.push_back(ring(n, 0, 0, 5, [](double) { return 16.0; }));
  rings.push_back(ring(n, 0, 0, 5, [](double) { return 7.0; }));
  rings.push_back(ring(n, 0, 0, 11, [](double) { return 7.0; }));
  // The head: an ellipsoid (semi-axes 13 and 10 mm across, 17 mm up) centred 28 mm up, never
  // narrower than the neck below its middle, its centre leaning forward 0.35 mm per mm of height.
  for (int k = 0; k < 16; ++k) {
    const double s = -0.9 + 1.87 * k / 15, z = 28 + 17 * s, w = std::sqrt(1 - s * s);
    const double a = s < 0 ? std::max(7.0, 13 * w) : 13 * w, b = s < 0 ? std::max(7.0, 10 * w) : 10 * w;
    rings.push_back(ring(n, 0.35 * (z - 11), 0, z, [&](double t) {
      return a * b / std::hypot(b * std::cos(t), a * std::sin(t));  // the ellipse's radius at t
    }));
  }
  return ring_stack(rings);
}

// A block on a flat sx × sy base whose top is the height field `top(x, y)` (> 0), sampled on an
// nx × ny grid: a box with a rounded or tilted top.
template <typename Top>
core::Mesh block(double sx, double sy, int nx, int ny, Top&& top) {
  core::Mesh m;
  const auto id = [&](int level, int i, int j) {
    return static_cast<std::uint32_t>((level * (ny + 1) + j) * (nx + 1) + i);
  };
  for (int level = 0; level < 2; ++level)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const double x = sx * i / nx, y = sy * j / ny;
        m.positions.push_back({x, y, level == 0 ? 0.0 : top(x, y)});
      }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.triangles.push_back({id(0, i, j), id(0, i + 1, j + 1), id(0, i + 1, j)});  // bottom, facing down
      m.triangles.push_back({id(0, i, j), id(0, i, j + 1), id(0, i + 1, j + 1)});
      m.triangles.push_back({id(1, i, j), id(1, i + 1, j), id(1, i + 1, j + 1)});  // top, facing up
      m.triangles.push_back({id(1, i, j), id(1, i + 1, j + 1), id(1, i, j + 1)});
    }
  // The walls, walking the boundary counter-clockwise seen from above.
  std::vector<std::pair<int, int>> ring;
  for (int i = 0; i < nx; ++i) ring.emplace_back(i, 0);
  for (int j = 0; j < ny; ++j) ring.emplace_back(nx, j);
  for (int i = nx; i > 0; --i) ring.emplace_back(i, ny);
  for (int j = ny; j > 0; --j) ring.emplace_back(0, j);
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const auto [i0, j0] = ring[k];
    const auto [i1, j1] = ring[(k + 1) % ring.size()];
    m.triangles.push_back({id(0, i0, j0), id(0, i1, j1), id(1, i1, j1)});
    m.triangles.push_back({id(0, i0, j0), id(1, i1, j1), id(1, i0, j0)});
  }
  return m;
}

// A boat-like block: 60 × 30 mm on its flat bottom, its top curving up from 8 mm at the stern to
// 18 mm at the bow (no flat top to stand on instead).
inline core::Mesh ramp_block() {
  return block(60, 30, 30, 15,
               [](double x, double y) { return 8 + 10 * (x / 60) * (x / 60) + 2 * std::sin(M_PI * y / 30); });
}

}  // namespace salient::test
