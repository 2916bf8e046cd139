#include "core/saliency/saliency_cache.hpp"

#include <cstring>

namespace salient::core {
namespace {

// Two independent 64-bit FNV-1a streams (different offsets) over the bytes the method reads:
// a collision would need both to collide on meshes of the same size.
class Digest {
 public:
  void add(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      a_ = (a_ ^ p[i]) * 0x100000001b3ULL;
      b_ = (b_ ^ p[i]) * 0x100000001b3ULL;
      b_ ^= b_ >> 29;
    }
  }
  template <class T>
  void add_all(const std::vector<T>& v) {
    const std::uint64_t n = v.size();
    add(&n, sizeof n);
    if (!v.empty()) add(v.data(), v.size() * sizeof(T));
  }
  std::string text() const { return std::to_string(a_) + ":" + std::to_string(b_); }

 private:
  std::uint64_t a_ = 0xcbf29ce484222325ULL, b_ = 0x84222325cbf29ce4ULL;
};

std::string key_of(const Mesh& mesh, SaliencyMethod method) {
  Digest d;
  d.add_all(mesh.positions);
  d.add_all(mesh.triangles);
  if (method == SaliencyMethod::painted) d.add_all(mesh.quality), d.add_all(mesh.colors);
  return std::string(saliency_method_name(method)) + ":" + d.text();
}

}  // namespace

std::vector<float> SaliencyCache::get(const Mesh& mesh, SaliencyMethod method, const std::string& source,
                                      const RunContext& run) {
  if (method == SaliencyMethod::uniform || capacity_ == 0) return compute_saliency(mesh, method, source, run);
  const std::string key = key_of(mesh, method);
  {
    std::lock_guard lock(mutex_);
    for (auto it = entries_.begin(); it != entries_.end(); ++it)
      if (it->first == key) {
        entries_.splice(entries_.begin(), entries_, it);
        ++hits_;
        return entries_.front().second;
      }
  }
  std::vector<float> values = compute_saliency(mesh, method, source, run);  // outside the lock
  ++misses_;
  std::lock_guard lock(mutex_);
  entries_.emplace_front(key, values);
  while (entries_.size() > capacity_) entries_.pop_back();
  return values;
}

}  // namespace salient::core
