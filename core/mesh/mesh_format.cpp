// MeshFormat detection. Content wins over the extension: a binary STL whose 80-byte header
// starts with "solid" is still binary when its size matches the triangle count.
#include "core/mesh/mesh_format.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <string>

namespace salient::core {
namespace {

std::string_view skip_space(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

bool starts_with_word(std::string_view s, std::string_view word) {
  if (s.substr(0, word.size()) != word) return false;
  return s.size() == word.size() || std::isspace(static_cast<unsigned char>(s[word.size()]));
}

std::string lower_extension(std::string_view name) {
  const auto dot = name.rfind('.');
  if (dot == std::string_view::npos) return {};
  std::string ext(name.substr(dot + 1));
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool binary_stl_size_matches(std::string_view bytes) {
  if (bytes.size() < 84) return false;
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);  // little endian on every platform we build for
  return 84 + 50 * static_cast<std::uint64_t>(count) == bytes.size();
}

bool is_off_header(std::string_view s) {
  // [ST][C][N][4][n]OFF, optionally followed by " BINARY" or the counts.
  std::size_t end = 0;
  while (end < s.size() && !std::isspace(static_cast<unsigned char>(s[end]))) ++end;
  const std::string_view word = s.substr(0, end);
  return word.size() >= 3 && word.size() <= 8 && word.substr(word.size() - 3) == "OFF";
}

bool looks_like_obj(std::string_view s) {
  // The first meaningful line of an OBJ is a comment or one of its statements.
  for (std::string_view kw : {"v", "vt", "vn", "f", "o", "g", "s", "mtllib", "usemtl", "#"}) {
    if (starts_with_word(s, kw) || (kw == "#" && s.substr(0, 1) == "#")) return true;
  }
  return false;
}

}  // namespace

std::string_view format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::stl_ascii:
      return "STL (ASCII)";
    case MeshFormat::stl_binary:
      return "STL (binary)";
    case MeshFormat::obj:
      return "OBJ";
    case MeshFormat::ply:
      return "PLY";
    case MeshFormat::off:
      return "OFF";
  }
  return "unknown";
}

std::optional<MeshFormat> detect_format(std::string_view bytes, std::string_view file_name) {
  if (binary_stl_size_matches(bytes)) return MeshFormat::stl_binary;
  const std::string_view text = skip_space(bytes);
  if (bytes.substr(0, 3) == "ply" && bytes.size() > 3 && (bytes[3] == '\n' || bytes[3] == '\r'))
    return MeshFormat::ply;
  if (is_off_header(text)) return MeshFormat::off;
  if (starts_with_word(text, "solid")) {
    // ASCII STL names its facets early; a binary file with a "solid" header does not.
    if (bytes.substr(0, 1024).find("facet") != std::string_view::npos ||
        bytes.substr(0, 1024).find("endsolid") != std::string_view::npos)
      return MeshFormat::stl_ascii;
    if (bytes.size() >= 84) return MeshFormat::stl_binary;
  }
  if (looks_like_obj(text)) return MeshFormat::obj;
  const std::string ext = lower_extension(file_name);
  if (ext == "stl") return bytes.size() >= 84 ? MeshFormat::stl_binary : MeshFormat::stl_ascii;
  if (ext == "obj") return MeshFormat::obj;
  if (ext == "ply") return MeshFormat::ply;
  if (ext == "off") return MeshFormat::off;
  return std::nullopt;
}

}  // namespace salient::core
