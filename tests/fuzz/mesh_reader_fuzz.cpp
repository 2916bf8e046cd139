// Fuzz target for the mesh readers: any bytes must end in a mesh or an InputError, never a
// crash, a hang or another exception. The first byte picks the parser so each is reached
// directly, and whatever loads goes on through repair and placement.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/common/input_error.hpp"
#include "core/mesh/format_readers.hpp"
#include "core/mesh/mesh_repair.hpp"
#include "core/mesh/placement.hpp"

using namespace salient::core;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    MeshFile file;
    switch (data[0] % 6) {
      case 0:
        file = detail::read_stl_ascii(bytes, "fuzz.stl");
        break;
      case 1:
        file = detail::read_stl_binary(bytes, "fuzz.stl");
        break;
      case 2:
        file = detail::read_obj(bytes, "fuzz.obj");
        break;
      case 3:
        file = detail::read_off(bytes, "fuzz.off");
        break;
      case 4:
        file = detail::read_ply(bytes, "fuzz.ply");
        break;
      default:
        file = read_mesh(bytes, "fuzz.bin");
        break;
    }
    for (const Triangle& t : file.mesh.triangles)
      for (std::uint32_t v : t)
        if (v >= file.mesh.positions.size()) std::abort();  // a reader let a bad index through
    repair_mesh(file.mesh);
    if (!file.mesh.triangles.empty()) {
      PlacementOptions placement;
      placement.scale = 2.0;
      place_mesh(file.mesh, placement);
    }
  } catch (const InputError&) {
  }
  return 0;
}
