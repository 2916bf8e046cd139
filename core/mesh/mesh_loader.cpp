// load_mesh: read, repair, and reject meshes that nothing printable is left of.
#include "core/mesh/mesh_loader.hpp"

#include <algorithm>

#include "core/common/input_error.hpp"

namespace salient::core {

LoadedMesh repair_loaded(MeshFile file, const std::string& source, const RepairOptions& options) {
  LoadedMesh out;
  out.format = file.format;
  out.polygons = file.polygons;
  out.triangles_read = file.mesh.triangle_count();
  out.vertices_read = file.mesh.vertex_count();
  out.mesh = std::move(file.mesh);
  out.repair = repair_mesh(out.mesh, options);
  if (out.mesh.triangles.empty()) {
    throw InputError(source, {},
                     "no usable triangles: all " + std::to_string(out.triangles_read) +
                         " faces are degenerate (zero area or repeated vertices)");
  }
  return out;
}

Mesh file_surface(const LoadedMesh& loaded) {
  Mesh out = loaded.mesh;
  out.triangles.resize(out.triangles.size() - std::min(loaded.repair.cap_faces, out.triangles.size()));
  return out;
}

LoadedMesh load_mesh(const std::filesystem::path& path, const RepairOptions& options) {
  return repair_loaded(read_mesh_file(path), path.filename().string(), options);
}

LoadedMesh load_mesh(std::string_view bytes, const std::string& source, const RepairOptions& options) {
  return repair_loaded(read_mesh(bytes, source), source, options);
}

}  // namespace salient::core
