// PlyHeader: the parsed header of a PLY file (format, elements and their properties).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace salient::core::detail {

enum class PlyEncoding { ascii, binary_little_endian, binary_big_endian };
enum class PlyScalar { i8, u8, i16, u16, i32, u32, f32, f64 };

std::size_t scalar_size(PlyScalar type);

struct PlyProperty {
  std::string name;
  PlyScalar type = PlyScalar::f32;  // the value type (of the items, for a list)
  bool is_list = false;
  PlyScalar count_type = PlyScalar::u8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::uint64_t line = 0;  // of its "element" line, for errors

  int find(std::string_view property) const;  // index or -1
  // Fewest bytes one instance can take in this encoding (lists of length zero).
  std::uint64_t min_bytes(PlyEncoding encoding) const;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  // first byte after "end_header\n"
  std::uint64_t body_line = 0;  // line number of the body's first line (ASCII)
};

// Parses the header; throws InputError with the line of any problem. Element counts are
// checked against the bytes that follow the header.
PlyHeader parse_ply_header(std::string_view bytes, const std::string& source);

}  // namespace salient::core::detail
