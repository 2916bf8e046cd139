// VertexAdjacency: each vertex's edge neighbours (one-ring), in compressed rows.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh/mesh.hpp"

namespace salient::core {

class VertexAdjacency {
 public:
  explicit VertexAdjacency(const Mesh& mesh);

  std::span<const std::uint32_t> neighbours(std::size_t v) const {
    return {ids_.data() + start_[v], ids_.data() + start_[v + 1]};
  }
  std::size_t vertex_count() const { return start_.size() - 1; }

 private:
  std::vector<std::uint32_t> start_;
  std::vector<std::uint32_t> ids_;
};

}  // namespace salient::core
