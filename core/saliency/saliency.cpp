// Saliency inputs that need no computation: uniform and painted.
#include "core/saliency/saliency.hpp"

#include <algorithm>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

std::vector<float> normalised(std::vector<float> v) {
  if (v.empty()) return v;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const float a = *lo, b = *hi;
  for (float& x : v) x = b > a ? (x - a) / (b - a) : 1.0f;  // a constant paint means "all equal"
  return v;
}

}  // namespace

std::optional<SaliencyMethod> parse_saliency_method(std::string_view name) {
  if (name == "uniform") return SaliencyMethod::uniform;
  if (name == "painted") return SaliencyMethod::painted;
  return std::nullopt;
}

std::string_view saliency_method_name(SaliencyMethod method) {
  switch (method) {
    case SaliencyMethod::uniform: return "uniform";
    case SaliencyMethod::painted: return "painted";
  }
  return "uniform";
}

std::vector<float> compute_saliency(const Mesh& mesh, SaliencyMethod method, const std::string& source,
                                    const RunContext& run) {
  run.check();
  switch (method) {
    case SaliencyMethod::uniform: return std::vector<float>(mesh.vertex_count(), 1.0f);
    case SaliencyMethod::painted:
      if (mesh.has_quality()) return normalised(mesh.quality);
      if (mesh.has_colors()) {
        std::vector<float> red(mesh.vertex_count());
        for (std::size_t i = 0; i < red.size(); ++i) red[i] = mesh.colors[i].r;
        return normalised(std::move(red));
      }
      throw InputError(source, {}, "--saliency painted needs vertex quality or vertex colours, and the model has neither");
  }
  return {};
}

}  // namespace salient::core
