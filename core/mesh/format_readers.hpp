// The per-format parsers behind read_mesh (internal to core/mesh).
#pragma once

#include <string>
#include <string_view>

#include "core/common/input_error.hpp"
#include "core/mesh/mesh_reader.hpp"

namespace salient::core::detail {

MeshFile read_stl_ascii(std::string_view bytes, const std::string& source);
MeshFile read_stl_binary(std::string_view bytes, const std::string& source);
MeshFile read_obj(std::string_view bytes, const std::string& source);
MeshFile read_off(std::string_view bytes, const std::string& source);
MeshFile read_ply(std::string_view bytes, const std::string& source);

// Checks a vertex read from a file: non-finite coordinates are an error at `where`.
void check_finite(const Vec3& p, const std::string& source, const InputLocation& where);

}  // namespace salient::core::detail
