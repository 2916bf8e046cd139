// Mesh sections. A face crossing the plane yields one segment, oriented so the solid is on its
// left: it starts where a face edge (in winding order) goes from above the plane to below and
// ends where one goes from below to above. Segments are chained through the mesh edge they
// share, so loops follow the mesh's topology rather than coordinate matching.
#include "core/geometry/mesh_section.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace salient::core {
namespace {

struct Segment {
  Point2 start, end;
  std::uint64_t start_edge, end_edge;
};

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

Point2 crossing(const Vec3& a, const Vec3& b, double z) {
  const double t = (z - a.z) / (b.z - a.z);
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
}

// The segment where face `t` crosses z, if it does.
bool face_segment(const Mesh& mesh, const Triangle& t, double z, Segment& seg) {
  bool above[3];
  for (int k = 0; k < 3; ++k) above[k] = mesh.positions[t[k]].z >= z;
  if (above[0] == above[1] && above[1] == above[2]) return false;
  bool have_start = false, have_end = false;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t a = t[k], b = t[(k + 1) % 3];
    const bool ua = above[k], ub = above[(k + 1) % 3];
    if (ua && !ub) {
      seg.start = crossing(mesh.positions[a], mesh.positions[b], z);
      seg.start_edge = edge_key(a, b);
      have_start = true;
    } else if (!ua && ub) {
      seg.end = crossing(mesh.positions[a], mesh.positions[b], z);
      seg.end_edge = edge_key(a, b);
      have_end = true;
    }
  }
  return have_start && have_end;
}

void push_point(Polygon& ring, const Point2& p) {
  if (ring.empty() || !(ring.back() == p)) ring.push_back(p);
}

double distance(const Point2& a, const Point2& b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}

// Where the mesh has holes the chains stay open. Joins each chain's end to the nearest start of
// another (within max_gap), then closes a chain whose ends are within max_gap; what is left is
// counted as open and left out.
void close_open_chains(std::vector<Polygon>& open, double max_gap, Section& section) {
  std::vector<bool> taken(open.size(), false);
  for (std::size_t a = 0; a < open.size(); ++a) {
    if (taken[a]) continue;
    taken[a] = true;
    Polygon ring = std::move(open[a]);
    std::size_t joined = 0;
    while (!ring.empty()) {
      const double self_gap = distance(ring.back(), ring.front());
      double best = self_gap;
      std::size_t best_b = open.size();
      for (std::size_t b = 0; b < open.size(); ++b) {
        if (taken[b] || open[b].empty()) continue;
        const double d = distance(ring.back(), open[b].front());
        if (d < best) best = d, best_b = b;
      }
      if (best_b == open.size() || best > max_gap) break;
      taken[best_b] = true;
      ring.insert(ring.end(), open[best_b].begin(), open[best_b].end());
      ++joined;
    }
    if (ring.size() >= 3 && distance(ring.back(), ring.front()) <= max_gap) {
      section.gaps_closed += joined + 1;
      section.loops.push_back(std::move(ring));
    } else {
      section.open_chains += joined + 1;
    }
  }
}

Section chain(const std::vector<Segment>& segs, const SectionOptions& options) {
  Section section;
  std::unordered_map<std::uint64_t, std::uint32_t> by_start;
  by_start.reserve(segs.size() * 2);
  std::unordered_map<std::uint64_t, std::uint32_t> ends;
  ends.reserve(segs.size() * 2);
  for (std::uint32_t i = 0; i < segs.size(); ++i) {
    by_start.emplace(segs[i].start_edge, i);
    ends.emplace(segs[i].end_edge, i);
  }
  std::vector<bool> used(segs.size(), false);
  std::vector<Polygon> open;
  auto walk = [&](std::uint32_t first) {
    Polygon ring;
    std::uint32_t i = first;
    bool closed = false;
    while (true) {
      used[i] = true;
      push_point(ring, segs[i].start);
      auto it = by_start.find(segs[i].end_edge);
      if (it == by_start.end()) {
        push_point(ring, segs[i].end);  // an open chain keeps its last point
        break;
      }
      if (it->second == first) {
        closed = true;
        break;
      }
      if (used[it->second]) break;
      i = it->second;
    }
    if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
    if (closed) {
      if (ring.size() >= 3) section.loops.push_back(std::move(ring));
    } else {
      open.push_back(std::move(ring));
    }
  };
  // Chain heads first (open chains), so an open chain is walked from its beginning.
  for (std::uint32_t i = 0; i < segs.size(); ++i)
    if (!used[i] && ends.find(segs[i].start_edge) == ends.end()) walk(i);
  for (std::uint32_t i = 0; i < segs.size(); ++i)
    if (!used[i]) walk(i);
  close_open_chains(open, options.max_gap, section);
  return section;
}

}  // namespace

std::vector<Section> section_mesh(const Mesh& mesh, std::span<const double> heights,
                                  const SectionOptions& options, const RunContext& run) {
  std::vector<std::size_t> plane_order(heights.size());
  std::iota(plane_order.begin(), plane_order.end(), 0);
  std::sort(plane_order.begin(), plane_order.end(),
            [&](std::size_t a, std::size_t b) { return heights[a] < heights[b]; });

  const std::size_t nf = mesh.triangle_count();
  std::vector<double> zmin(nf), zmax(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const Triangle& t = mesh.triangles[f];
    const double a = mesh.positions[t[0]].z, b = mesh.positions[t[1]].z, c = mesh.positions[t[2]].z;
    zmin[f] = std::min({a, b, c});
    zmax[f] = std::max({a, b, c});
  }
  std::vector<std::uint32_t> by_low(nf);
  std::iota(by_low.begin(), by_low.end(), 0u);
  std::sort(by_low.begin(), by_low.end(),
            [&](std::uint32_t a, std::uint32_t b) { return zmin[a] < zmin[b]; });

  std::vector<Section> out(heights.size());
  std::vector<std::uint32_t> active;
  std::vector<Segment> segs;
  std::size_t next = 0;
  for (std::size_t n = 0; n < plane_order.size(); ++n) {
    run.check();
    const double z = heights[plane_order[n]];
    while (next < nf && zmin[by_low[next]] < z) active.push_back(by_low[next++]);
    // Faces wholly below the plane are done for this and every higher plane.
    std::erase_if(active, [&](std::uint32_t f) { return zmax[f] < z; });
    segs.clear();
    Segment seg{};
    for (std::uint32_t f : active)
      if (face_segment(mesh, mesh.triangles[f], z, seg)) segs.push_back(seg);
    out[plane_order[n]] = chain(segs, options);
    run.report("sections", static_cast<double>(n + 1) / plane_order.size());
  }
  return out;
}

}  // namespace salient::core
