// lee05: mean curvature 𝒞; G(𝒞, σ) the Gaussian-weighted average over Euclidean neighbours
// within 2σ; level i: |G(𝒞, σi) − G(𝒞, 2σi)| at σi ∈ {2,3,4,5,6}·ε, ε = 0.3 % of the bounding
// box diagonal; each level non-linearly normalised; summed and scaled to [0, 1].
// One neighbour pass per vertex (radius 24ε, the widest filter) feeds all eight distinct σ.
#include "core/saliency/lee05_saliency.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/geometry/point_grid.hpp"
#include "core/mesh/vertex_adjacency.hpp"
#include "core/saliency/mesh_curvature.hpp"

namespace salient::core {
namespace {

constexpr std::array<double, 8> sigmas = {2, 3, 4, 5, 6, 8, 10, 12};                              // in ε
constexpr std::array<std::array<int, 2>, 5> levels = {{{0, 2}, {1, 4}, {2, 5}, {3, 6}, {4, 7}}};  // σ, 2σ

std::vector<double> normalised(std::vector<double> v) {
  if (v.empty()) return v;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const double a = *lo, b = *hi;
  for (double& x : v) x = b > a ? (x - a) / (b - a) : 0.0;
  return v;
}

}  // namespace

std::vector<double> suppress_non_maxima(const std::vector<double>& values, const Mesh& mesh) {
  std::vector<double> v = normalised(values);
  const VertexAdjacency adj(mesh);
  double sum = 0;
  std::size_t count = 0;
  bool skipped_global = false;
  for (std::size_t i = 0; i < v.size(); ++i) {
    bool is_max = true;
    for (std::uint32_t j : adj.neighbours(i)) {
      if (v[j] > v[i]) is_max = false;
      for (std::uint32_t k : adj.neighbours(j))
        if (v[k] > v[i]) is_max = false;
      if (!is_max) break;
    }
    if (!is_max) continue;
    if (v[i] == 1.0 && !skipped_global) {
      skipped_global = true;  // the global maximum itself
      continue;
    }
    sum += v[i];
    ++count;
  }
  const double mean_max = count ? sum / count : 0;
  const double factor = (1 - mean_max) * (1 - mean_max);
  for (double& x : v) x *= factor;
  return v;
}

std::vector<float> lee05_saliency(const Mesh& mesh, const RunContext& run) {
  const std::size_t n = mesh.vertex_count();
  const double eps = 0.003 * bounding_box(mesh).diagonal();
  const std::vector<double> curvature = mean_curvature(mesh);
  const double radius = 2 * sigmas.back() * eps;
  const PointGrid grid(mesh.positions, radius);
  std::vector<std::array<double, 8>> filtered(n);
  constexpr std::size_t block = 4096;
  for (std::size_t first = 0; first < n; first += block) {
    run.check();
    run.report("lee05", static_cast<double>(first) / n);
    const std::size_t last = std::min(n, first + block);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(first, last),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          std::array<double, 8> num{}, den{};
                          grid.for_each_within(mesh.positions[i], radius, [&](std::uint32_t j, double d2) {
                            for (std::size_t s = 0; s < sigmas.size(); ++s) {
                              const double sigma = sigmas[s] * eps;
                              if (d2 > 4 * sigma * sigma) continue;
                              const double w = std::exp(-d2 / (2 * sigma * sigma));
                              num[s] += w * curvature[j];
                              den[s] += w;
                            }
                          });
                          for (std::size_t s = 0; s < sigmas.size(); ++s)
                            filtered[i][s] = den[s] > 0 ? num[s] / den[s] : 0;
                        }
                      });
  }
  std::vector<double> total(n, 0);
  for (const auto& [a, b] : levels) {
    std::vector<double> level(n);
    for (std::size_t i = 0; i < n; ++i) level[i] = std::fabs(filtered[i][a] - filtered[i][b]);
    const std::vector<double> s = suppress_non_maxima(level, mesh);
    for (std::size_t i = 0; i < n; ++i) total[i] += s[i];
  }
  const std::vector<double> out = normalised(std::move(total));
  run.report("lee05", 1.0);
  return std::vector<float>(out.begin(), out.end());
}

}  // namespace salient::core
