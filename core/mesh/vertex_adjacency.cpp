// VertexAdjacency: gather both directions of every triangle edge, sort each row, drop repeats.
#include "core/mesh/vertex_adjacency.hpp"

#include <algorithm>

namespace salient::core {

VertexAdjacency::VertexAdjacency(const Mesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  std::vector<std::uint32_t> count(n + 1, 0);
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) count[t[k] + 1] += 2;
  for (std::size_t v = 0; v < n; ++v) count[v + 1] += count[v];
  std::vector<std::uint32_t> raw(count.back());
  std::vector<std::uint32_t> fill(count.begin(), count.end() - 1);
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      raw[fill[t[k]]++] = t[(k + 1) % 3];
      raw[fill[t[k]]++] = t[(k + 2) % 3];
    }
  start_.assign(n + 1, 0);
  ids_.reserve(raw.size() / 2);
  for (std::size_t v = 0; v < n; ++v) {
    auto first = raw.begin() + count[v], last = raw.begin() + count[v + 1];
    std::sort(first, last);
    last = std::unique(first, last);
    ids_.insert(ids_.end(), first, last);
    start_[v + 1] = static_cast<std::uint32_t>(ids_.size());
  }
}

}  // namespace salient::core
