// PLY reader: ASCII and binary (little and big endian) bodies; `vertex` with x/y/z, optional
// red/green/blue (integer or float) and quality; `face` lists (fan-triangulated) and
// `tristrips` with -1 restarts; every other element and property is skipped.
#include <algorithm>
#include <cmath>

#include "core/mesh/byte_cursor.hpp"
#include "core/mesh/format_readers.hpp"
#include "core/mesh/ply_header.hpp"
#include "core/mesh/text_cursor.hpp"

namespace salient::core::detail {
namespace {

// One stream of scalars, from either encoding, with errors located by line or byte.
class PlyValues {
 public:
  PlyValues(std::string_view bytes, const std::string& source, const PlyHeader& header)
      : encoding_(header.encoding),
        bin_(bytes, source, header.body_offset),
        text_(bytes.substr(header.body_offset), source, header.body_line) {}

  double read(PlyScalar type, std::string_view what) {
    if (encoding_ == PlyEncoding::ascii) return text_.parse_double(text_.expect_token(what), what);
    const Endian e = encoding_ == PlyEncoding::binary_big_endian ? Endian::big : Endian::little;
    switch (type) {
      case PlyScalar::i8:
        return bin_.read<std::int8_t>(e, what);
      case PlyScalar::u8:
        return bin_.read<std::uint8_t>(e, what);
      case PlyScalar::i16:
        return bin_.read<std::int16_t>(e, what);
      case PlyScalar::u16:
        return bin_.read<std::uint16_t>(e, what);
      case PlyScalar::i32:
        return bin_.read<std::int32_t>(e, what);
      case PlyScalar::u32:
        return bin_.read<std::uint32_t>(e, what);
      case PlyScalar::f32:
        return bin_.read<float>(e, what);
      case PlyScalar::f64:
        return bin_.read<double>(e, what);
    }
    return 0;
  }

  // An integer value (list counts, indices): non-integers are an error.
  std::int64_t read_int(PlyScalar type, std::string_view what) {
    const double v = read(type, what);
    if (!std::isfinite(v) || v != std::floor(v) || std::fabs(v) > 9.0e15)
      fail(std::string(what) + " is not an integer");
    return static_cast<std::int64_t>(v);
  }

  void skip_list_items(PlyScalar type, std::int64_t n, std::string_view what) {
    if (encoding_ != PlyEncoding::ascii) {
      bin_.skip(static_cast<std::uint64_t>(n) * scalar_size(type), what);
      return;
    }
    for (std::int64_t i = 0; i < n; ++i) read(type, what);
  }

  // Rejects a list length the rest of the file cannot hold before anything is sized by it.
  void check_list_length(std::int64_t n, PlyScalar type, std::string_view what) {
    // ASCII items take a digit and a separator, but the last one may end the file.
    const std::uint64_t each = encoding_ == PlyEncoding::ascii ? 2 : scalar_size(type);
    const std::uint64_t room = remaining() + (encoding_ == PlyEncoding::ascii ? 1 : 0);
    if (n < 0) fail(std::string(what) + " has a negative length");
    if (static_cast<std::uint64_t>(n) > room / each)
      fail(std::string(what) + " declares " + std::to_string(n) +
           " items, more than the rest of the file holds");
  }

  InputLocation where() const {
    return encoding_ == PlyEncoding::ascii ? InputLocation::at_line(text_.line_number())
                                           : InputLocation::at_byte(bin_.offset());
  }
  const std::string& source() const { return bin_.source(); }
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(bin_.source(), where(), message);
  }

 private:
  std::size_t remaining() const {
    return encoding_ == PlyEncoding::ascii ? text_.remaining() : bin_.remaining();
  }

  PlyEncoding encoding_;
  ByteCursor bin_;
  TextCursor text_;
};

double color_scale(PlyScalar type) {
  switch (type) {
    case PlyScalar::u8:
    case PlyScalar::i8:
      return 1.0 / 255.0;
    case PlyScalar::u16:
    case PlyScalar::i16:
      return 1.0 / 65535.0;
    default:
      return 1.0;
  }
}

struct VertexSlots {
  int x = -1, y = -1, z = -1, red = -1, green = -1, blue = -1, quality = -1;
};

VertexSlots find_vertex_slots(const PlyElement& e) {
  VertexSlots s{e.find("x"),     e.find("y"),    e.find("z"),      e.find("red"),
                e.find("green"), e.find("blue"), e.find("quality")};
  if (s.red < 0) s.red = e.find("diffuse_red");
  if (s.green < 0) s.green = e.find("diffuse_green");
  if (s.blue < 0) s.blue = e.find("diffuse_blue");
  if (s.red < 0) s.red = e.find("r");
  if (s.green < 0) s.green = e.find("g");
  if (s.blue < 0) s.blue = e.find("b");
  return s;
}

void read_vertices(PlyValues& in, const PlyElement& e, Mesh& mesh) {
  const VertexSlots s = find_vertex_slots(e);
  if (s.x < 0 || s.y < 0 || s.z < 0) in.fail("element 'vertex' lacks an x, y or z property");
  const bool colors = s.red >= 0 && s.green >= 0 && s.blue >= 0;
  mesh.positions.reserve(e.count);
  if (colors) mesh.colors.reserve(e.count);
  if (s.quality >= 0) mesh.quality.reserve(e.count);
  std::vector<double> values(e.properties.size());
  for (std::uint64_t i = 0; i < e.count; ++i) {
    const InputLocation at = in.where();
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (p.is_list) {
        const std::int64_t n = in.read_int(p.count_type, "a vertex list length");
        in.check_list_length(n, p.type, "vertex list '" + p.name + "'");
        in.skip_list_items(p.type, n, "vertex list '" + p.name + "'");
      } else {
        values[k] = in.read(p.type, "vertex property '" + p.name + "'");
      }
    }
    const Vec3 pos{values[s.x], values[s.y], values[s.z]};
    check_finite(pos, in.source(), at);
    mesh.positions.push_back(pos);
    if (colors) {
      auto c = [&](int slot) {
        const double v = values[slot] * color_scale(e.properties[slot].type);
        return static_cast<float>(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0));
      };
      mesh.colors.push_back({c(s.red), c(s.green), c(s.blue)});
    }
    if (s.quality >= 0) {
      const double q = values[s.quality];
      mesh.quality.push_back(std::isfinite(q) ? static_cast<float>(q) : 0.0f);
    }
  }
}

// Reads one index list; indices must name a declared vertex (or be -1 in a strip).
void read_index_list(PlyValues& in, const PlyProperty& p, std::uint64_t vertex_count, bool strip,
                     std::vector<std::int64_t>& out) {
  const std::int64_t n = in.read_int(p.count_type, "a face list length");
  in.check_list_length(n, p.type, "face list '" + p.name + "'");
  out.clear();
  out.reserve(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t v = in.read_int(p.type, "a vertex index");
    if ((v < 0 && !(strip && v == -1)) || (v >= 0 && static_cast<std::uint64_t>(v) >= vertex_count))
      in.fail("vertex index " + std::to_string(v) + " is out of range (" + std::to_string(vertex_count) +
              " vertices)");
    out.push_back(v);
  }
}

void add_fan(const std::vector<std::int64_t>& ids, Mesh& mesh) {
  for (std::size_t k = 1; k + 1 < ids.size(); ++k)
    mesh.triangles.push_back({static_cast<std::uint32_t>(ids[0]), static_cast<std::uint32_t>(ids[k]),
                              static_cast<std::uint32_t>(ids[k + 1])});
}

// A strip a b c d … makes (a b c), (c b d), (c d e), …: every other triangle is reversed to keep
// one orientation. Triangles with a repeated index are the strip's joints, not surface.
std::size_t add_strip(const std::vector<std::int64_t>& ids, Mesh& mesh) {
  std::size_t added = 0;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= ids.size(); ++i) {
    if (i < ids.size() && ids[i] != -1) continue;
    for (std::size_t k = start + 2; k < i; ++k) {
      const auto a = static_cast<std::uint32_t>(ids[k - 2]);
      const auto b = static_cast<std::uint32_t>(ids[k - 1]);
      const auto c = static_cast<std::uint32_t>(ids[k]);
      if (a == b || b == c || a == c) continue;
      mesh.triangles.push_back((k - start) % 2 == 0 ? Triangle{a, b, c} : Triangle{b, a, c});
      ++added;
    }
    start = i + 1;
  }
  return added;
}

}  // namespace

MeshFile read_ply(std::string_view bytes, const std::string& source) {
  const PlyHeader header = parse_ply_header(bytes, source);
  const PlyElement* vertex = nullptr;
  for (const PlyElement& e : header.elements)
    if (e.name == "vertex") vertex = &e;
  if (!vertex) throw InputError(source, {}, "PLY header has no 'vertex' element");
  const std::uint64_t vertex_count = vertex->count;
  if (vertex_count >= UINT32_MAX) throw InputError(source, {}, "too many vertices");

  MeshFile out{{}, MeshFormat::ply, 0};
  PlyValues in(bytes, source, header);
  std::vector<std::int64_t> ids;
  for (const PlyElement& e : header.elements) {
    const bool faces = e.name == "face";
    const bool strips = e.name == "tristrips";
    if (&e == vertex) {
      read_vertices(in, e, out.mesh);
      continue;
    }
    const int list = (faces || strips) ? std::max(e.find("vertex_indices"), e.find("vertex_index")) : -1;
    if ((faces || strips) && (list < 0 || !e.properties[list].is_list))
      in.fail("element '" + e.name + "' has no 'vertex_indices' list");
    for (std::uint64_t i = 0; i < e.count; ++i) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        if (static_cast<int>(k) == list) {
          read_index_list(in, p, vertex_count, strips, ids);
          if (faces) {
            if (ids.size() < 3) in.fail("face has " + std::to_string(ids.size()) + " vertices, needs 3");
            add_fan(ids, out.mesh);
            ++out.polygons;
          } else {
            out.polygons += add_strip(ids, out.mesh);
          }
        } else if (p.is_list) {
          const std::int64_t n = in.read_int(p.count_type, "a list length");
          in.check_list_length(n, p.type, "list '" + p.name + "'");
          in.skip_list_items(p.type, n, "list '" + p.name + "'");
        } else {
          in.read(p.type, "property '" + p.name + "'");
        }
      }
    }
  }
  if (out.mesh.triangles.empty()) throw InputError(source, {}, "no faces in file");
  return out;
}

}  // namespace salient::core::detail
