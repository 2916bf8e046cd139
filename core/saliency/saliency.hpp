// Per-vertex saliency in [0, 1]: how much a viewer looks at each part of the surface
// (ALGORITHMS.md §1): computed (`spectral`, `lee05`) or given (`painted`, `uniform`).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

enum class SaliencyMethod { spectral, lee05, painted, uniform };

// The name table: "spectral", "lee05", "painted", "uniform" (in this order), and back.
const std::vector<std::string_view>& saliency_method_names();
std::optional<SaliencyMethod> parse_saliency_method(std::string_view name);
std::string_view saliency_method_name(SaliencyMethod method);
inline std::string_view to_string(SaliencyMethod method) {
  return saliency_method_name(method);
}

// One value in [0, 1] per vertex of `mesh`. `painted` takes the vertex quality (else the red
// channel of the vertex colour), min-max normalised; a mesh with neither is an InputError
// naming `source`.
std::vector<float> compute_saliency(const Mesh& mesh, SaliencyMethod method, const std::string& source,
                                    const RunContext& run = {});

// A user's per-vertex values: one number per line ('#' comments and blank lines skipped), as
// many as `vertex_count`. Throws InputError naming the file and line.
std::vector<float> read_vertex_values(const std::filesystem::path& path, std::size_t vertex_count);

}  // namespace salient::core
