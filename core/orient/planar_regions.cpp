// Planar regions by region growing over shared edges. The region's plane is refitted (mean
// normal, centroid) as it grows, and every face is held to it, so a gently curved surface cannot
// creep into one region face by face.
#include "core/orient/planar_regions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <tuple>

namespace salient::core {
namespace {

// Each face's neighbours across its edges, in compressed rows.
struct FaceAdjacency {
  std::vector<std::uint32_t> start, ids;

  explicit FaceAdjacency(const Mesh& mesh) {
    std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>> edges;
    edges.reserve(3 * mesh.triangle_count());
    for (std::uint32_t f = 0; f < mesh.triangle_count(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = mesh.triangles[f][k], b = mesh.triangles[f][(k + 1) % 3];
        edges.emplace_back(std::min(a, b), std::max(a, b), f);
      }
    std::sort(edges.begin(), edges.end());
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      while (j < edges.size() && std::get<0>(edges[j]) == std::get<0>(edges[i]) &&
             std::get<1>(edges[j]) == std::get<1>(edges[i]))
        ++j;
      for (std::size_t p = i; p < j; ++p)
        for (std::size_t q = i; q < j; ++q)
          if (p != q) pairs.emplace_back(std::get<2>(edges[p]), std::get<2>(edges[q]));
      i = j;
    }
    start.assign(mesh.triangle_count() + 1, 0);
    for (const auto& [f, g] : pairs) ++start[f + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    ids.resize(pairs.size());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (const auto& [f, g] : pairs) ids[fill[f]++] = g;
  }
};

Vec3 centroid_of(const Mesh& mesh, std::size_t f) {
  const Triangle& t = mesh.triangles[f];
  return (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.0;
}

}  // namespace

std::vector<PlanarRegion> planar_regions(const Mesh& mesh, double max_angle, double max_distance) {
  const std::size_t n = mesh.triangle_count();
  std::vector<double> area(n);
  std::vector<Vec3> normal(n);
  for (std::size_t f = 0; f < n; ++f) {
    const Vec3 c = area_normal(mesh, f);
    const double twice = norm(c);
    area[f] = std::isfinite(twice) ? twice / 2 : 0;
    normal[f] = area[f] > 0 ? c / twice : Vec3{};
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return area[a] > area[b]; });
  const FaceAdjacency adjacency(mesh);
  const double min_cos = std::cos(max_angle);
  std::vector<char> taken(n, 0);
  std::vector<PlanarRegion> regions;
  std::vector<std::uint32_t> queue;
  for (std::uint32_t seed : order) {
    if (taken[seed] || !(area[seed] > 0)) continue;
    PlanarRegion r;
    Vec3 weighted_normal{}, weighted_centroid{};
    const auto add = [&](std::uint32_t f) {
      taken[f] = 1;
      r.faces.push_back(f);
      r.area += area[f];
      weighted_normal += normal[f] * area[f];
      weighted_centroid += centroid_of(mesh, f) * area[f];
      r.normal = weighted_normal / norm(weighted_normal);
      r.centroid = weighted_centroid / r.area;
    };
    const auto fits = [&](std::uint32_t f) {
      if (!(area[f] > 0) || dot(normal[f], r.normal) < min_cos) return false;
      for (std::uint32_t v : mesh.triangles[f])
        if (std::fabs(dot(mesh.positions[v] - r.centroid, r.normal)) > max_distance) return false;
      return true;
    };
    add(seed);
    queue.assign(1, seed);
    while (!queue.empty()) {
      const std::uint32_t f = queue.back();
      queue.pop_back();
      for (std::uint32_t i = adjacency.start[f]; i < adjacency.start[f + 1]; ++i) {
        const std::uint32_t g = adjacency.ids[i];
        if (!taken[g] && fits(g)) add(g), queue.push_back(g);
      }
    }
    regions.push_back(std::move(r));
  }
  std::stable_sort(regions.begin(), regions.end(),
                   [](const PlanarRegion& a, const PlanarRegion& b) { return a.area > b.area; });
  return regions;
}

bool projects_inside(const Mesh& mesh, const PlanarRegion& region, const Vec3& p) {
  const Vec3& n = region.normal;
  // Any two directions across n: the test is on the region's plane.
  const Vec3 u = std::fabs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0});
  const Vec3 un = u / norm(u), vn = cross(n, un);
  const auto flat = [&](const Vec3& q) { return std::array<double, 2>{dot(q, un), dot(q, vn)}; };
  const auto side = [](const std::array<double, 2>& a, const std::array<double, 2>& b,
                       const std::array<double, 2>& c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  };
  const auto q = flat(p);
  for (std::uint32_t f : region.faces) {
    const Triangle& t = mesh.triangles[f];
    const auto a = flat(mesh.positions[t[0]]), b = flat(mesh.positions[t[1]]), c = flat(mesh.positions[t[2]]);
    const double s0 = side(a, b, q), s1 = side(b, c, q), s2 = side(c, a, q);
    if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) return true;
  }
  return false;
}

}  // namespace salient::core
