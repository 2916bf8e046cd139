// find_cut. For each direction the vertices are projected once; each face then visits only the
// offsets its projection spans (seam pieces), and the parts' areas and saliency come from prefix
// sums over the faces sorted by centroid, so a direction costs O(F log F), not O(F × offsets).
#include "core/segment/seam_search.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/saliency/mesh_curvature.hpp"

namespace salient::core {
namespace {

std::vector<double> seam_weights(const Mesh& mesh, std::span<const float> saliency, double lambda1) {
  const std::vector<double> H = mean_curvature(mesh);
  std::vector<double> magnitude;
  magnitude.reserve(H.size());
  for (double h : H)
    if (std::isfinite(h)) magnitude.push_back(std::fabs(h));
  double scale = 0;
  if (!magnitude.empty()) {
    const auto p90 = magnitude.begin() + static_cast<std::ptrdiff_t>(0.9 * (magnitude.size() - 1));
    std::nth_element(magnitude.begin(), p90, magnitude.end());
    scale = *p90;
  }
  float s_max = 0;
  for (float s : saliency) s_max = std::max(s_max, s);
  std::vector<double> w(mesh.vertex_count(), 0);
  for (std::size_t v = 0; v < w.size(); ++v) {
    const double q = scale > 0 && std::isfinite(H[v]) ? std::clamp(H[v] / scale, -1.0, 1.0) : 0;
    const double s = s_max > 0 ? saliency[v] / s_max : 0;
    w[v] = q + lambda1 * s;
  }
  return w;
}

struct DirectionResult {
  std::optional<SeamCandidate> best;
};

}  // namespace

std::optional<SeamCandidate> find_cut(const Mesh& mesh, std::span<const float> saliency, const SeamOptions& o,
                                      const RunContext& run) {
  const std::vector<SeamCandidate> best = find_cuts(mesh, saliency, 1, o, run);
  if (best.empty()) return std::nullopt;
  return best.front();
}

std::vector<SeamCandidate> find_cuts(const Mesh& mesh, std::span<const float> saliency, int count,
                                     const SeamOptions& o, const RunContext& run) {
  if (mesh.triangles.empty() || o.directions < 1 || o.offsets < 1 || count < 1) return {};
  const std::vector<double> weight = seam_weights(mesh, saliency, o.lambda1);
  float s_max = 0;
  for (float s : saliency) s_max = std::max(s_max, s);
  const std::size_t F = mesh.triangle_count();
  std::vector<double> area(F), face_s(F);
  double total_area = 0;
  for (std::size_t f = 0; f < F; ++f) {
    area[f] = 0.5 * norm(area_normal(mesh, f));
    if (!std::isfinite(area[f])) area[f] = 0;
    const Triangle& t = mesh.triangles[f];
    face_s[f] = s_max > 0 ? (saliency[t[0]] + saliency[t[1]] + saliency[t[2]]) / (3.0 * s_max) : 0;
    total_area += area[f];
  }
  if (!(total_area > 0)) return {};

  std::vector<DirectionResult> results(o.directions);
  const auto search_direction = [&](int di) {
    const double angle = M_PI * di / o.directions;
    CutPlane plane{std::cos(angle), std::sin(angle), 0};
    std::vector<double> t(mesh.vertex_count());
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t v = 0; v < t.size(); ++v)
      t[v] = plane.nx * mesh.positions[v].x + plane.ny * mesh.positions[v].y;
    for (const Triangle& tri : mesh.triangles)
      for (std::uint32_t v : tri) lo = std::min(lo, t[v]), hi = std::max(hi, t[v]);
    const double step = (hi - lo) / o.offsets;
    if (!(step > 0)) return;
    const auto offset_of = [&](int j) { return lo + (j + 0.5) * step; };
    // The seam: Σ length and Σ length × mean weight of its pieces, per offset.
    std::vector<double> length(o.offsets, 0), integral(o.offsets, 0);
    // The parts: faces sorted by the projection of their centroid.
    std::vector<std::pair<double, std::size_t>> order(F);
    for (std::size_t f = 0; f < F; ++f) {
      const Triangle& tri = mesh.triangles[f];
      const double a = t[tri[0]], b = t[tri[1]], c = t[tri[2]];
      order[f] = {(a + b + c) / 3, f};
      const double fmin = std::min({a, b, c}), fmax = std::max({a, b, c});
      const int j_first = std::max(0, static_cast<int>(std::ceil((fmin - lo) / step - 0.5)));
      const int j_last = std::min(o.offsets - 1, static_cast<int>(std::floor((fmax - lo) / step - 0.5)));
      for (int j = j_first; j <= j_last; ++j) {
        const double off = offset_of(j);
        Vec3 ends[2];
        double w[2];
        int n = 0;
        for (int e = 0; e < 3 && n < 2; ++e) {
          const std::uint32_t u = tri[e], v = tri[(e + 1) % 3];
          if ((t[u] < off) == (t[v] < off)) continue;
          const double s = (off - t[u]) / (t[v] - t[u]);
          ends[n] = mesh.positions[u] + (mesh.positions[v] - mesh.positions[u]) * s;
          w[n] = weight[u] + (weight[v] - weight[u]) * s;
          ++n;
        }
        if (n < 2) continue;
        const double len = norm(ends[1] - ends[0]);
        length[j] += len;
        integral[j] += len * 0.5 * (w[0] + w[1]);
      }
    }
    std::sort(order.begin(), order.end());
    std::vector<double> area_prefix(F + 1, 0), s_prefix(F + 1, 0);
    for (std::size_t k = 0; k < F; ++k) {
      area_prefix[k + 1] = area_prefix[k] + area[order[k].second];
      s_prefix[k + 1] = s_prefix[k] + area[order[k].second] * face_s[order[k].second];
    }
    DirectionResult& r = results[di];
    for (int j = 0; j < o.offsets; ++j) {
      if (!(length[j] > 0)) continue;
      const double off = offset_of(j);
      const std::size_t k =
          std::lower_bound(order.begin(), order.end(), std::make_pair(off, std::size_t{0})) - order.begin();
      const double a0 = area_prefix[k], a1 = total_area - a0;
      const double share = std::min(a0, a1) / total_area;
      if (share < o.min_share) continue;
      const double d = std::fabs(s_prefix[k] / a0 - (s_prefix[F] - s_prefix[k]) / a1);
      SeamCandidate c;
      c.plane = {plane.nx, plane.ny, off};
      c.seam_mean = integral[j] / length[j];
      c.difference = d;
      c.length = length[j];
      c.share = share;
      c.cost = c.seam_mean - o.lambda2 * d;
      if (!r.best || c.cost < r.best->cost) r.best = c;
    }
  };
  // In blocks, so progress is reported from the calling thread.
  constexpr int block = 8;
  for (int first = 0; first < o.directions; first += block) {
    run.check();
    run.report("segment", 0.3 * first / o.directions);
    tbb::parallel_for(first, std::min(o.directions, first + block), search_direction);
  }
  std::vector<SeamCandidate> best;
  for (const DirectionResult& r : results)
    if (r.best) best.push_back(*r.best);
  // Stable: equal costs keep direction order, so the answer is the same every run.
  std::stable_sort(best.begin(), best.end(),
                   [](const SeamCandidate& a, const SeamCandidate& b) { return a.cost < b.cost; });
  if (best.size() > static_cast<std::size_t>(count)) best.resize(count);
  return best;
}

}  // namespace salient::core
