// PLY header parsing (http://paulbourke.net/dataformats/ply/ and the common type aliases).
#include "core/mesh/ply_header.hpp"

#include <optional>

#include "core/mesh/text_cursor.hpp"

namespace salient::core::detail {
namespace {

std::optional<PlyScalar> scalar_from_name(std::string_view name) {
  if (name == "char" || name == "int8") return PlyScalar::i8;
  if (name == "uchar" || name == "uint8") return PlyScalar::u8;
  if (name == "short" || name == "int16") return PlyScalar::i16;
  if (name == "ushort" || name == "uint16") return PlyScalar::u16;
  if (name == "int" || name == "int32") return PlyScalar::i32;
  if (name == "uint" || name == "uint32") return PlyScalar::u32;
  if (name == "float" || name == "float32") return PlyScalar::f32;
  if (name == "double" || name == "float64") return PlyScalar::f64;
  return std::nullopt;
}

}  // namespace

std::size_t scalar_size(PlyScalar type) {
  switch (type) {
    case PlyScalar::i8:
    case PlyScalar::u8:
      return 1;
    case PlyScalar::i16:
    case PlyScalar::u16:
      return 2;
    case PlyScalar::i32:
    case PlyScalar::u32:
    case PlyScalar::f32:
      return 4;
    case PlyScalar::f64:
      return 8;
  }
  return 1;
}

int PlyElement::find(std::string_view property) const {
  for (std::size_t i = 0; i < properties.size(); ++i)
    if (properties[i].name == property) return static_cast<int>(i);
  return -1;
}

std::uint64_t PlyElement::min_bytes(PlyEncoding encoding) const {
  std::uint64_t total = 0;
  for (const PlyProperty& p : properties) {
    if (encoding == PlyEncoding::ascii)
      total += 2;  // a digit and a separator
    else
      total += scalar_size(p.is_list ? p.count_type : p.type);
  }
  return total;
}

PlyHeader parse_ply_header(std::string_view bytes, const std::string& source) {
  TextCursor cur(bytes, source);
  PlyHeader header;
  std::string_view line;
  cur.next_line(line);
  if (line != "ply") cur.fail("not a PLY file (first line must be 'ply')");
  bool have_format = false;
  while (true) {
    if (!cur.next_line(line)) cur.fail("unexpected end of file in the header: no 'end_header'");
    LineTokens tokens(line);
    std::string_view kw;
    if (!tokens.next(kw)) continue;
    if (kw == "comment" || kw == "obj_info") continue;
    if (kw == "end_header") break;
    std::string_view a, b, c, d;
    if (kw == "format") {
      if (!tokens.next(a) || !tokens.next(b)) cur.fail("'format' needs an encoding and a version");
      if (a == "ascii")
        header.encoding = PlyEncoding::ascii;
      else if (a == "binary_little_endian")
        header.encoding = PlyEncoding::binary_little_endian;
      else if (a == "binary_big_endian")
        header.encoding = PlyEncoding::binary_big_endian;
      else
        cur.fail("unknown PLY encoding '" + std::string(a) + "'");
      if (b != "1.0") cur.fail("unsupported PLY version '" + std::string(b) + "'");
      have_format = true;
    } else if (kw == "element") {
      if (!tokens.next(a) || !tokens.next(b)) cur.fail("'element' needs a name and a count");
      const std::int64_t count = cur.parse_int(b, "the element count");
      if (count < 0) cur.fail("negative element count");
      header.elements.push_back({std::string(a), static_cast<std::uint64_t>(count), {}, cur.line_number()});
    } else if (kw == "property") {
      if (header.elements.empty()) cur.fail("'property' before any 'element'");
      PlyProperty prop;
      if (!tokens.next(a)) cur.fail("'property' needs a type and a name");
      if (a == "list") {
        if (!tokens.next(b) || !tokens.next(c) || !tokens.next(d))
          cur.fail("'property list' needs two types and a name");
        const auto count_type = scalar_from_name(b);
        const auto item_type = scalar_from_name(c);
        if (!count_type || !item_type) cur.fail("unknown property type in 'property list'");
        if (*count_type == PlyScalar::f32 || *count_type == PlyScalar::f64)
          cur.fail("list count type must be an integer type");
        prop = {std::string(d), *item_type, true, *count_type};
      } else {
        const auto type = scalar_from_name(a);
        if (!type) cur.fail("unknown property type '" + std::string(a) + "'");
        if (!tokens.next(b)) cur.fail("'property' needs a name");
        prop = {std::string(b), *type, false, PlyScalar::u8};
      }
      header.elements.back().properties.push_back(std::move(prop));
    } else {
      cur.fail("unknown header keyword '" + std::string(kw.substr(0, 40)) + "'");
    }
  }
  if (!have_format) cur.fail("header has no 'format' line");
  header.body_offset = cur.offset();
  header.body_line = cur.line_number() + 1;
  // Every instance takes at least min_bytes, so counts beyond that are lies (or an attack).
  std::uint64_t room = bytes.size() - header.body_offset;
  for (const PlyElement& e : header.elements) {
    const std::uint64_t each = e.min_bytes(header.encoding);
    if (each > 0 && e.count > room / each) {
      throw InputError(source, InputLocation::at_line(e.line),
                       "element '" + e.name + "' declares " + std::to_string(e.count) +
                           " entries, more than the " + std::to_string(bytes.size() - header.body_offset) +
                           "-byte body can hold");
    }
    if (each == 0 && e.count > 0)
      throw InputError(source, InputLocation::at_line(e.line),
                       "element '" + e.name + "' has entries but no properties");
    room -= e.count * each;
  }
  return header;
}

}  // namespace salient::core::detail
