// Hole loops from the directed edges used once (reversed: the cap's own edges), then ear clipping
// of each loop projected on the plane of its Newell normal. O(n²) per loop of n edges.
#include "core/mesh/hole_filler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

namespace salient::core {
namespace {

struct P2 {
  double x, y;
};

double cross2(const P2& o, const P2& a, const P2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

bool inside_triangle(const P2& p, const P2& a, const P2& b, const P2& c) {
  return cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0;
}

// The cap edges: each edge used by one face, reversed, keyed by its start vertex. Edges used by
// two or more faces are no hole's.
std::multimap<std::uint32_t, std::uint32_t> cap_edges(const Mesh& mesh) {
  std::unordered_map<std::uint64_t, std::uint32_t> uses;
  uses.reserve(mesh.triangles.size() * 3);
  const auto key = [](std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
  };
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++uses[key(t[k], t[(k + 1) % 3])];
  std::multimap<std::uint32_t, std::uint32_t> out;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      if (uses[key(a, b)] == 1) out.emplace(b, a);
    }
  return out;
}

// Ear clipping of `loop` (vertex ids in cap order); false when it folds over itself in plan, or
// when the point-in-ear tests would pass `budget` (a hostile loop of many reflex vertices is cubic
// work): the hole is then left open, refused later if it matters.
bool clip_ears(const Mesh& mesh, const std::vector<std::uint32_t>& loop, std::vector<Triangle>& out,
               std::size_t& budget) {
  Vec3 normal, centre;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec3& a = mesh.positions[loop[i]];
    const Vec3& b = mesh.positions[loop[(i + 1) % loop.size()]];
    normal += cross(a, b);  // Newell: twice the projected area
    centre += a;
  }
  const double length = norm(normal);
  if (!(length > 0)) return false;
  normal = normal / length;
  centre = centre / static_cast<double>(loop.size());
  const Vec3 helper = std::abs(normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 u = cross(helper, normal);
  u = u / norm(u);
  const Vec3 v = cross(normal, u);  // u × v = normal: the loop runs counter-clockwise in (u, v)
  std::vector<P2> p(loop.size());
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec3 d = mesh.positions[loop[i]] - centre;
    p[i] = {dot(d, u), dot(d, v)};
  }
  std::vector<std::size_t> left(loop.size());
  for (std::size_t i = 0; i < left.size(); ++i) left[i] = i;
  std::vector<Triangle> caps;
  while (left.size() > 3) {
    const std::size_t n = left.size();
    bool clipped = false;
    for (std::size_t k = 0; k < n && !clipped; ++k) {
      const std::size_t a = left[(k + n - 1) % n], b = left[k], c = left[(k + 1) % n];
      if (cross2(p[a], p[b], p[c]) <= 0) continue;  // reflex or flat: no ear
      if (budget < n) return false;
      budget -= n;
      bool empty = true;
      for (std::size_t j : left)
        if (j != a && j != b && j != c && inside_triangle(p[j], p[a], p[b], p[c])) {
          empty = false;
          break;
        }
      if (!empty) continue;
      caps.push_back({loop[a], loop[b], loop[c]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
    }
    if (!clipped) return false;
  }
  if (cross2(p[left[0]], p[left[1]], p[left[2]]) <= 0) return false;
  caps.push_back({loop[left[0]], loop[left[1]], loop[left[2]]});
  out.insert(out.end(), caps.begin(), caps.end());
  return true;
}

}  // namespace

HoleFilling fill_holes(Mesh& mesh, std::size_t max_edges) {
  HoleFilling report;
  std::multimap<std::uint32_t, std::uint32_t> edges = cap_edges(mesh);
  // A vertex with two holes' edges leaving it (a pinch) makes the walk ambiguous: those loops stay.
  std::unordered_map<std::uint32_t, std::size_t> leaving;
  for (const auto& [from, to] : edges) ++leaving[from];
  std::vector<Triangle> caps;
  std::size_t budget = std::size_t{1} << 26;  // point-in-ear tests for the whole mesh: well under a second
  // A lone triangle (or a face of a sheet whose three edges are all open) is its own hole: its
  // cap would be the face reversed, a solid of no volume. Such loops are left.
  std::unordered_map<std::uint64_t, int> faces;
  const auto face_key = [](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    std::uint32_t v[3] = {a, b, c};
    std::sort(v, v + 3);
    return (std::uint64_t{v[0]} << 42) ^ (std::uint64_t{v[1]} << 21) ^ v[2];  // a clash only leaves a hole
  };
  for (const Triangle& t : mesh.triangles) ++faces[face_key(t[0], t[1], t[2])];
  while (!edges.empty()) {
    const std::uint32_t start = edges.begin()->first;
    std::vector<std::uint32_t> loop;
    bool simple = true;
    std::uint32_t at = start;
    while (true) {
      const auto it = edges.find(at);
      if (it == edges.end()) {
        simple = false;  // a chain that does not come back
        break;
      }
      simple = simple && leaving[at] == 1;
      loop.push_back(at);
      at = it->second;
      edges.erase(it);
      if (at == start) break;
    }
    const bool lone_face = loop.size() == 3 && faces.count(face_key(loop[0], loop[1], loop[2])) > 0;
    if (!simple || loop.size() < 3 || loop.size() > max_edges || lone_face ||
        !clip_ears(mesh, loop, caps, budget)) {
      ++report.holes_left;
      continue;
    }
    ++report.holes_filled;
  }
  report.faces_added = caps.size();
  mesh.triangles.insert(mesh.triangles.end(), caps.begin(), caps.end());
  return report;
}

}  // namespace salient::core
