// write_ply: binary little endian; writes to a temporary name and renames, so a reader never
// sees half a file.
#include "core/mesh/ply_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <string>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

template <typename T>
void put(std::string& out, T v) {
  static_assert(std::endian::native == std::endian::little, "PLY writer assumes a little-endian host");
  char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  out.append(raw, sizeof(T));
}

std::uint8_t byte(float v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255));
}

}  // namespace

std::string ply_bytes(const Mesh& mesh, std::span<const float> quality, std::span<const Color> colors) {
  const bool q = quality.size() == mesh.vertex_count() && !quality.empty();
  const bool c = colors.size() == mesh.vertex_count() && !colors.empty();
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by salient\nelement vertex " +
                    std::to_string(mesh.vertex_count()) +
                    "\nproperty float x\nproperty float y\nproperty float z\n";
  if (q) out += "property float quality\n";
  if (c) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(mesh.triangle_count()) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
    const Vec3& p = mesh.positions[i];
    put(out, static_cast<float>(p.x));
    put(out, static_cast<float>(p.y));
    put(out, static_cast<float>(p.z));
    if (q) put(out, quality[i]);
    if (c) {
      put(out, byte(colors[i].r));
      put(out, byte(colors[i].g));
      put(out, byte(colors[i].b));
    }
  }
  for (const Triangle& t : mesh.triangles) {
    put(out, std::uint8_t{3});
    for (std::uint32_t v : t) put(out, static_cast<std::int32_t>(v));
  }
  return out;
}

void write_ply(const std::filesystem::path& path, const Mesh& mesh, std::span<const float> quality,
               std::span<const Color> colors) {
  const std::string out = ply_bytes(mesh, quality, colors);
  const std::filesystem::path tmp = path.string() + ".part";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f.write(out.data(), static_cast<std::streamsize>(out.size()));
    if (!f) throw InputError(path.filename().string(), {}, "cannot write");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path.filename().string(), {}, "cannot write: " + ec.message());
}

}  // namespace salient::core
