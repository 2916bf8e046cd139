// load_mesh: read a model file, repair it and refuse what cannot be printed.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "core/mesh/mesh_reader.hpp"
#include "core/mesh/mesh_repair.hpp"

namespace salient::core {

struct LoadedMesh {
  Mesh mesh;  // repaired
  MeshFormat format;
  std::size_t polygons = 0;        // faces in the file
  std::size_t triangles_read = 0;  // after triangulation, before repair
  std::size_t vertices_read = 0;
  RepairReport repair;
};

// The surface the file describes, without the caps repair closed its holes with: what saliency is
// computed on (a cap is no surface a viewer sees; it adds no vertex, so per-vertex values carry).
Mesh file_surface(const LoadedMesh& loaded);

// Throws InputError for unreadable files and for meshes with no usable triangle left.
LoadedMesh load_mesh(const std::filesystem::path& path, const RepairOptions& options = {});
LoadedMesh load_mesh(std::string_view bytes, const std::string& source, const RepairOptions& options = {});
// The repair half of load_mesh, for a file already read (and perhaps given per-vertex values).
LoadedMesh repair_loaded(MeshFile file, const std::string& source, const RepairOptions& options = {});

}  // namespace salient::core
