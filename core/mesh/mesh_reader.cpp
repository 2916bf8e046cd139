// read_mesh: format dispatch, whole-file reading, and the checks common to every format.
#include "core/mesh/mesh_reader.hpp"

#include <fstream>
#include <system_error>

#include "core/common/input_error.hpp"
#include "core/mesh/format_readers.hpp"

namespace salient::core {

namespace detail {

void check_finite(const Vec3& p, const std::string& source, const InputLocation& where) {
  if (!is_finite(p))
    throw InputError(source, where, "vertex coordinate is not a finite number (NaN or infinity)");
}

}  // namespace detail

MeshFile read_mesh(std::string_view bytes, const std::string& source) {
  if (bytes.empty()) throw InputError(source, {}, "file is empty");
  const auto format = detect_format(bytes, source);
  if (!format) {
    throw InputError(source, {}, "unrecognised mesh format (expected STL, OBJ, PLY or OFF)");
  }
  switch (*format) {
    case MeshFormat::stl_ascii:
      return detail::read_stl_ascii(bytes, source);
    case MeshFormat::stl_binary:
      return detail::read_stl_binary(bytes, source);
    case MeshFormat::obj:
      return detail::read_obj(bytes, source);
    case MeshFormat::off:
      return detail::read_off(bytes, source);
    case MeshFormat::ply:
      return detail::read_ply(bytes, source);
  }
  throw InputError(source, {}, "unrecognised mesh format");
}

MeshFile read_mesh_file(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(name, {}, "is a directory, not a mesh file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(name, {}, "cannot read: " + ec.message());
  if (size > max_mesh_file_bytes) {
    throw InputError(name, {},
                     "file is " + std::to_string(size) + " bytes, more than the " +
                         std::to_string(max_mesh_file_bytes) + "-byte limit");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, {}, "cannot open for reading");
  std::string bytes(size, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uint64_t>(in.gcount()) != size) throw InputError(name, {}, "read failed");
  return read_mesh(bytes, name);
}

}  // namespace salient::core
