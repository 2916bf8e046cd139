// Per-vertex saliency in [0, 1]: how much a viewer looks at each part of the surface.
// Step 2 has the inputs that need no computation; Step 3 adds `spectral` and `lee05`.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/progress.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::core {

enum class SaliencyMethod { uniform, painted };

std::optional<SaliencyMethod> parse_saliency_method(std::string_view name);
std::string_view saliency_method_name(SaliencyMethod method);

// One value in [0, 1] per vertex of `mesh`. `painted` takes the vertex quality (else the red
// channel of the vertex colour), min-max normalised; a mesh with neither is an InputError
// naming `source`.
std::vector<float> compute_saliency(const Mesh& mesh, SaliencyMethod method, const std::string& source,
                                    const RunContext& run = {});

}  // namespace salient::core
