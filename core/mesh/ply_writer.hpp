// Writing a mesh as binary PLY with per-vertex quality and colour (MeshLab, Blender, CloudCompare
// read both).
#pragma once

#include <filesystem>
#include <span>
#include <string>

#include "core/mesh/mesh.hpp"

namespace salient::core {

// The file's bytes. `quality` and `colors` may be empty; otherwise one entry per vertex.
std::string ply_bytes(const Mesh& mesh, std::span<const float> quality, std::span<const Color> colors);

// `quality` and `colors` may be empty; otherwise one entry per vertex. Throws InputError if the
// file cannot be written.
void write_ply(const std::filesystem::path& path, const Mesh& mesh, std::span<const float> quality,
               std::span<const Color> colors);

}  // namespace salient::core
