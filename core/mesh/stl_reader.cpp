// STL readers: binary (80-byte header, uint32 count, 50-byte facets) and ASCII (one or more
// `solid` blocks). STL repeats each corner per facet; identical corners are merged here so the
// mesh is indexed, and near-identical ones are welded later by repair().
#include <cstring>
#include <unordered_map>

#include "core/mesh/byte_cursor.hpp"
#include "core/mesh/format_readers.hpp"
#include "core/mesh/text_cursor.hpp"

namespace salient::core::detail {
namespace {

struct Vec3Hash {
  std::size_t operator()(const Vec3& v) const {
    std::uint64_t h = 1469598103934665603ull;
    for (double c : {v.x, v.y, v.z}) {
      std::uint64_t bits;
      c = c == 0.0 ? 0.0 : c;  // +0 and -0 are the same corner
      std::memcpy(&bits, &c, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
      h ^= h >> 29;
    }
    return static_cast<std::size_t>(h);
  }
};

class CornerIndex {
 public:
  CornerIndex(Mesh& mesh, std::size_t expected) : mesh_(mesh) { map_.reserve(expected); }
  std::uint32_t index_of(Vec3 p) {
    if (p.x == 0.0) p.x = 0.0;
    if (p.y == 0.0) p.y = 0.0;
    if (p.z == 0.0) p.z = 0.0;
    auto [it, inserted] = map_.try_emplace(p, static_cast<std::uint32_t>(mesh_.positions.size()));
    if (inserted) mesh_.positions.push_back(p);
    return it->second;
  }

 private:
  Mesh& mesh_;
  std::unordered_map<Vec3, std::uint32_t, Vec3Hash> map_;
};

constexpr std::size_t stl_header_bytes = 84;
constexpr std::size_t stl_facet_bytes = 50;

}  // namespace

MeshFile read_stl_binary(std::string_view bytes, const std::string& source) {
  ByteCursor cur(bytes, source);
  cur.skip(80, "the 80-byte STL header");
  const std::uint32_t count = cur.read<std::uint32_t>(Endian::little, "the triangle count");
  const std::uint64_t needed = stl_header_bytes + stl_facet_bytes * std::uint64_t{count};
  if (needed > bytes.size()) {
    cur.fail_at(80, "file is truncated: header declares " + std::to_string(count) + " triangles (" +
                        std::to_string(needed) + " bytes), file has " + std::to_string(bytes.size()) +
                        " bytes");
  }
  MeshFile out{{}, MeshFormat::stl_binary, count};
  out.mesh.triangles.reserve(count);
  CornerIndex corners(out.mesh, count / 2 + 3);
  for (std::uint32_t f = 0; f < count; ++f) {
    cur.skip(12, "a facet normal");
    Triangle tri{};
    for (int k = 0; k < 3; ++k) {
      const std::size_t at = cur.offset();
      Vec3 p;
      p.x = cur.read<float>(Endian::little, "a vertex");
      p.y = cur.read<float>(Endian::little, "a vertex");
      p.z = cur.read<float>(Endian::little, "a vertex");
      check_finite(p, source, InputLocation::at_byte(at));
      tri[k] = corners.index_of(p);
    }
    cur.skip(2, "the facet attribute");
    out.mesh.triangles.push_back(tri);
  }
  return out;
}

MeshFile read_stl_ascii(std::string_view bytes, const std::string& source) {
  TextCursor cur(bytes, source);
  MeshFile out{{}, MeshFormat::stl_ascii, 0};
  // An ASCII facet takes at least ~100 bytes; never reserve beyond what the file can hold.
  CornerIndex corners(out.mesh, bytes.size() / 100);
  std::string_view tok;
  bool in_solid = false;
  while (cur.next_token(tok)) {
    if (tok == "solid") {
      if (in_solid) cur.fail("'solid' inside another solid (missing 'endsolid')");
      in_solid = true;
      cur.skip_rest_of_line();  // the solid's name
      continue;
    }
    if (tok == "endsolid") {
      if (!in_solid) cur.fail("'endsolid' without 'solid'");
      in_solid = false;
      cur.skip_rest_of_line();
      continue;
    }
    if (tok != "facet")
      cur.fail("expected 'facet' or 'endsolid', got '" + std::string(tok.substr(0, 40)) + "'");
    if (!in_solid) cur.fail("'facet' outside a 'solid' block");
    if (cur.expect_token("'normal'") != "normal") cur.fail("expected 'normal' after 'facet'");
    for (int k = 0; k < 3; ++k) cur.parse_double(cur.expect_token("a normal component"), "the facet normal");
    if (cur.expect_token("'outer'") != "outer" || cur.expect_token("'loop'") != "loop")
      cur.fail("expected 'outer loop'");
    std::vector<std::uint32_t> loop;
    while (true) {
      tok = cur.expect_token("'vertex' or 'endloop'");
      if (tok == "endloop") break;
      if (tok != "vertex")
        cur.fail("expected 'vertex' or 'endloop', got '" + std::string(tok.substr(0, 40)) + "'");
      Vec3 p;
      p.x = cur.parse_double(cur.expect_token("x"), "vertex x");
      p.y = cur.parse_double(cur.expect_token("y"), "vertex y");
      p.z = cur.parse_double(cur.expect_token("z"), "vertex z");
      check_finite(p, source, InputLocation::at_line(cur.line_number()));
      loop.push_back(corners.index_of(p));
    }
    if (cur.expect_token("'endfacet'") != "endfacet") cur.fail("expected 'endfacet'");
    if (loop.size() < 3) cur.fail("facet has " + std::to_string(loop.size()) + " vertices, needs 3");
    ++out.polygons;
    for (std::size_t k = 1; k + 1 < loop.size(); ++k)
      out.mesh.triangles.push_back({loop[0], loop[k], loop[k + 1]});
  }
  // A missing final 'endsolid' is common in exported files and loses nothing: accepted.
  if (out.mesh.triangles.empty()) cur.fail("no facets in file");
  return out;
}

}  // namespace salient::core::detail
