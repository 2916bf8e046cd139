// Reading meshes from STL (ASCII/binary), OBJ, PLY (ASCII/binary) and OFF files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/mesh/mesh.hpp"
#include "core/mesh/mesh_format.hpp"

namespace salient::core {

struct MeshFile {
  Mesh mesh;  // as read: unwelded duplicates and degenerate faces still there
  MeshFormat format;
  std::size_t polygons;  // faces in the file before triangulation (strips count their triangles)
};

// Largest file we read (bytes): bigger is refused before anything is allocated.
inline constexpr std::uint64_t max_mesh_file_bytes = std::uint64_t{2} << 30;

// Parses `bytes`; `source` names the input in error messages and its extension is the fallback
// for format detection. Throws InputError naming the source and the line or byte offset.
MeshFile read_mesh(std::string_view bytes, const std::string& source);

// Reads a whole file (error messages use the file's name, not its full path).
MeshFile read_mesh_file(const std::filesystem::path& path);

}  // namespace salient::core
