// SaliencyCache: per-vertex saliency kept for reuse, so that planning the same model again with
// other settings (ρ, planner, layer limits, printer speeds) does not recompute it. Owned by the
// caller (the daemon keeps one for its workers) and handed to prepare() through PlanOptions.
#pragma once

#include <atomic>
#include <cstdint>
#include <list>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::core {

class SaliencyCache {
 public:
  explicit SaliencyCache(std::size_t capacity = 4) : capacity_(capacity) {}

  // compute_saliency(mesh, method, source, run), or the values an earlier call computed for the
  // same method and the same mesh (positions, triangles, and for painted its quality and colours:
  // the key is a digest of exactly what the method reads). Least recently used entries go first.
  // Thread-safe; two threads missing on one key at once both compute.
  std::vector<float> get(const Mesh& mesh, SaliencyMethod method, const std::string& source,
                         const RunContext& run = {});

  std::uint64_t hits() const { return hits_.load(); }
  std::uint64_t misses() const { return misses_.load(); }  // computed (uniform is never kept)

 private:
  std::size_t capacity_;
  std::mutex mutex_;
  std::list<std::pair<std::string, std::vector<float>>> entries_;  // most recently used first
  std::atomic<std::uint64_t> hits_{0}, misses_{0};
};

}  // namespace salient::core
