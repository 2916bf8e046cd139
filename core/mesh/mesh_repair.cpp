// Mesh repair. Welding uses a uniform grid of the tolerance's size (27-cell search), edge
// topology a sort of the 3F half-edge keys, orientation a breadth-first walk across manifold
// edges that flips a face when it runs a shared edge the same way as its neighbour.
#include "core/mesh/mesh_repair.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "core/mesh/hole_filler.hpp"

namespace salient::core {
namespace {

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    std::uint64_t h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h);
  }
};

// Maps every vertex to a representative within `tol`; returns how many were merged.
std::size_t weld(Mesh& mesh, double tol) {
  const std::size_t n = mesh.positions.size();
  if (n == 0 || !(tol > 0)) return 0;
  std::vector<std::uint32_t> rep(n);
  // Cell -> first vertex kept in it; further kept vertices of the cell chain through `next`.
  std::unordered_map<CellKey, std::uint32_t, CellHash> grid;
  grid.reserve(n);
  constexpr std::uint32_t none = UINT32_MAX;
  std::vector<std::uint32_t> next(n, none);
  // Cells four tolerances wide: a vertex's neighbours within tol lie in the cells its tol-box
  // touches, on average 1.5 per axis instead of 3.
  const double inv = 1.0 / (4 * tol), tol2 = tol * tol;
  const auto cell = [inv](double v) { return static_cast<std::int64_t>(std::floor(v * inv)); };
  std::size_t merged = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec3& p = mesh.positions[i];
    const CellKey c{cell(p.x), cell(p.y), cell(p.z)};
    std::int64_t found = -1;
    for (std::int64_t x = cell(p.x - tol); x <= cell(p.x + tol) && found < 0; ++x)
      for (std::int64_t y = cell(p.y - tol); y <= cell(p.y + tol) && found < 0; ++y)
        for (std::int64_t z = cell(p.z - tol); z <= cell(p.z + tol) && found < 0; ++z) {
          auto it = grid.find({x, y, z});
          if (it == grid.end()) continue;
          for (std::uint32_t j = it->second; j != none; j = next[j]) {
            const Vec3 d = mesh.positions[j] - p;
            if (dot(d, d) <= tol2) {
              found = j;
              break;
            }
          }
        }
    if (found >= 0) {
      rep[i] = static_cast<std::uint32_t>(found);
      ++merged;
    } else {
      rep[i] = i;
      auto [it, inserted] = grid.try_emplace(c, i);
      if (!inserted) {
        next[i] = it->second;
        it->second = i;
      }
    }
  }
  if (merged > 0)
    for (Triangle& t : mesh.triangles)
      for (std::uint32_t& v : t) v = rep[v];
  return merged;
}

std::size_t remove_unused_vertices(Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  constexpr std::uint32_t unused = UINT32_MAX;
  std::vector<std::uint32_t> remap(n, unused);
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t) remap[v] = 0;
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (remap[i] == unused) continue;
    remap[i] = next;
    mesh.positions[next] = mesh.positions[i];
    if (mesh.has_colors()) mesh.colors[next] = mesh.colors[i];
    if (mesh.has_quality()) mesh.quality[next] = mesh.quality[i];
    ++next;
  }
  mesh.positions.resize(next);
  if (mesh.has_colors()) mesh.colors.resize(next);
  if (mesh.has_quality()) mesh.quality.resize(next);
  for (Triangle& t : mesh.triangles)
    for (std::uint32_t& v : t) v = remap[v];
  return n - next;
}

std::size_t remove_degenerate_faces(Mesh& mesh) {
  const double diag = bounding_box(mesh).diagonal();
  const double min_double_area = 1e-14 * diag * diag;
  const std::size_t before = mesh.triangles.size();
  std::size_t out = 0;
  for (std::size_t t = 0; t < before; ++t) {
    const Triangle& tri = mesh.triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
    if (!(norm(area_normal(mesh, t)) > min_double_area)) continue;
    mesh.triangles[out++] = tri;
  }
  mesh.triangles.resize(out);
  return before - out;
}

std::size_t remove_duplicate_faces(Mesh& mesh) {
  const std::size_t n = mesh.triangles.size();
  std::vector<std::pair<Triangle, std::uint32_t>> keyed(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    Triangle k = mesh.triangles[t];
    std::sort(k.begin(), k.end());
    keyed[t] = {k, t};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<bool> keep(n, true);
  for (std::size_t i = 1; i < n; ++i)
    if (keyed[i].first == keyed[i - 1].first) keep[keyed[i].second] = false;
  std::size_t out = 0;
  for (std::size_t t = 0; t < n; ++t)
    if (keep[t]) mesh.triangles[out++] = mesh.triangles[t];
  mesh.triangles.resize(out);
  return n - out;
}

// One use of an undirected edge by a face; `forward` if the face runs it from lower to higher id.
struct EdgeUse {
  std::uint64_t key;
  std::uint32_t face;
  bool forward;
  bool operator<(const EdgeUse& o) const { return key < o.key || (key == o.key && face < o.face); }
};

// All half-edges grouped by undirected edge: a counting sort on the lower vertex id, then an
// insertion sort of each (tiny) bucket — linear time where a comparison sort of 3F keys is not.
std::vector<EdgeUse> edge_uses(const Mesh& mesh) {
  const std::size_t nv = mesh.vertex_count();
  std::vector<std::uint32_t> start(nv + 1, 0);
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++start[std::min(t[k], t[(k + 1) % 3]) + 1];
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<EdgeUse> uses(mesh.triangles.size() * 3);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      const std::uint32_t lo = std::min(a, b);
      uses[fill[lo]++] = {(std::uint64_t{lo} << 32) | std::max(a, b), f, a < b};
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    for (std::uint32_t i = start[v] + 1; i < start[v + 1]; ++i)
      for (std::uint32_t j = i; j > start[v] && uses[j] < uses[j - 1]; --j) std::swap(uses[j], uses[j - 1]);
  }
  return uses;
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

struct Neighbour {
  std::uint32_t face;
  bool same_direction;  // both faces run the shared edge the same way: one must flip
};

// Fills the topology fields of `report`; with `flip` non-null, also decides which faces to flip.
void analyse(const Mesh& mesh, RepairReport& report, std::vector<bool>* flip) {
  const std::size_t nf = mesh.triangles.size();
  const std::vector<EdgeUse> uses = edge_uses(mesh);
  UnionFind parts(nf);
  // A face has at most three manifold neighbours: fixed slots, no allocation per face.
  std::vector<std::array<Neighbour, 3>> adjacent(nf);
  std::vector<std::uint8_t> degree(nf, 0);
  std::vector<bool> on_open_edge(nf, false);
  report.boundary_edges = report.non_manifold_edges = 0;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    const std::size_t count = j - i;
    if (count == 1) ++report.boundary_edges;
    if (count > 2) ++report.non_manifold_edges;
    if (count != 2)
      for (std::size_t k = i; k < j; ++k) on_open_edge[uses[k].face] = true;
    for (std::size_t k = i + 1; k < j; ++k) parts.unite(uses[i].face, uses[k].face);
    if (count == 2 && uses[i].face != uses[i + 1].face) {
      const bool same = uses[i].forward == uses[i + 1].forward;
      const std::uint32_t f = uses[i].face, g = uses[i + 1].face;
      if (degree[f] < 3 && degree[g] < 3) {
        adjacent[f][degree[f]++] = {g, same};
        adjacent[g][degree[g]++] = {f, same};
      }
    }
    i = j;
  }
  report.components = 0;
  for (std::uint32_t f = 0; f < nf; ++f)
    if (parts.find(f) == f) ++report.components;
  report.watertight = nf > 0 && report.boundary_edges == 0 && report.non_manifold_edges == 0;

  // Orientation: walk each manifold-connected patch, assigning flips that agree across edges.
  std::vector<std::int8_t> state(nf, -1);  // -1 unvisited, else the flip bit
  report.orientable = true;
  std::vector<std::uint32_t> patch, todo;
  const Vec3 origin = bounding_box(mesh).center();
  for (std::uint32_t seed = 0; seed < nf; ++seed) {
    if (state[seed] >= 0) continue;
    patch.clear();
    todo.assign(1, seed);
    state[seed] = 0;
    bool closed = true;
    for (std::size_t head = 0; head < todo.size(); ++head) {
      const std::uint32_t f = todo[head];
      patch.push_back(f);
      closed = closed && !on_open_edge[f];
      for (int d = 0; d < degree[f]; ++d) {
        const Neighbour& nb = adjacent[f][d];
        const std::int8_t want = static_cast<std::int8_t>(state[f] ^ (nb.same_direction ? 1 : 0));
        if (state[nb.face] < 0) {
          state[nb.face] = want;
          todo.push_back(nb.face);
        } else if (state[nb.face] != want) {
          report.orientable = false;
        }
      }
    }
    if (!flip) continue;
    // Closed patch: face outward (positive volume). Open patch: keep the majority's orientation.
    bool invert;
    if (closed) {
      double six_volume = 0;
      for (std::uint32_t f : patch) {
        const Triangle& t = mesh.triangles[f];
        const Vec3 a = mesh.positions[t[0]] - origin, b = mesh.positions[t[1]] - origin,
                   c = mesh.positions[t[2]] - origin;
        six_volume += (state[f] ? -1.0 : 1.0) * dot(a, cross(b, c));
      }
      invert = six_volume < 0;
    } else {
      std::size_t flipped = 0;
      for (std::uint32_t f : patch) flipped += state[f];
      invert = 2 * flipped > patch.size();
    }
    for (std::uint32_t f : patch) (*flip)[f] = (state[f] != 0) != invert;
  }
}

}  // namespace

std::vector<std::string> RepairReport::lines() const {
  std::vector<std::string> out;
  auto say = [&out](std::size_t n, const char* what) {
    if (n > 0) out.push_back(std::to_string(n) + " " + what);
  };
  say(vertices_welded, "duplicate vertices welded");
  say(unused_vertices_removed, "unused vertices removed");
  say(degenerate_faces_removed, "degenerate faces removed");
  say(duplicate_faces_removed, "duplicate faces removed");
  say(faces_flipped, "faces flipped to a consistent orientation");
  say(holes_filled, "holes closed");
  say(boundary_edges, "open boundary edges left (mesh is not closed)");
  say(non_manifold_edges, "non-manifold edges left");
  if (!orientable) out.push_back("no consistent orientation exists (non-orientable surface)");
  return out;
}

RepairReport repair_mesh(Mesh& mesh, const RepairOptions& options) {
  RepairReport report;
  report.vertices_welded = weld(mesh, options.weld_tolerance * bounding_box(mesh).diagonal());
  report.degenerate_faces_removed = remove_degenerate_faces(mesh);
  report.duplicate_faces_removed = remove_duplicate_faces(mesh);
  report.unused_vertices_removed = remove_unused_vertices(mesh) - report.vertices_welded;
  // Flips to the orientation analyse decides; counts each face flipped.
  const auto orient = [&] {
    std::vector<bool> flip(mesh.triangles.size(), false);
    analyse(mesh, report, options.fix_orientation ? &flip : nullptr);
    for (std::size_t f = 0; f < flip.size(); ++f) {
      if (!flip[f]) continue;
      std::swap(mesh.triangles[f][1], mesh.triangles[f][2]);
      ++report.faces_flipped;
    }
  };
  orient();
  // Only an oriented mesh tells which side a cap faces. A part the caps close is oriented again:
  // open, it kept its majority's side, which may be inward; closed, it now faces outward.
  if (options.fill_holes && options.fix_orientation && report.orientable && report.boundary_edges > 0) {
    const HoleFilling filled = fill_holes(mesh);
    report.holes_filled = filled.holes_filled;
    report.cap_faces = filled.faces_added;
    if (report.holes_filled > 0) orient();
  }
  return report;
}

}  // namespace salient::core
