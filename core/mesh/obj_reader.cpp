// OBJ reader: `v x y z [w]` and `v x y z r g b` (colour), `f` with v, v/t, v//n, v/t/n corners,
// negative (relative) indices, polygons fan-triangulated. Materials, texture coordinates,
// normals, groups and smoothing are not needed for slicing and are skipped.
#include <algorithm>
#include <cmath>

#include "core/mesh/format_readers.hpp"
#include "core/mesh/text_cursor.hpp"

namespace salient::core::detail {
namespace {

struct PendingIndex {
  std::int64_t index;
  std::uint64_t line;
};

}  // namespace

MeshFile read_obj(std::string_view bytes, const std::string& source) {
  TextCursor cur(bytes, source);
  MeshFile out{{}, MeshFormat::obj, 0};
  Mesh& mesh = out.mesh;
  std::vector<Color> colors;
  std::size_t colored = 0;
  std::vector<PendingIndex> forward;  // positive indices beyond the vertices read so far
  std::vector<std::uint32_t> corners;
  std::string_view line;
  while (cur.next_line(line)) {
    LineTokens tokens(line);
    std::string_view kw;
    if (!tokens.next(kw) || kw.front() == '#') continue;
    if (kw == "v") {
      double values[7];
      int n = 0;
      std::string_view tok;
      while (tokens.next(tok) && tok.front() != '#') {
        if (n == 7) cur.fail("vertex has more than 7 values");
        values[n] = cur.parse_double(tok, "vertex coordinate");
        ++n;
      }
      if (n < 3) cur.fail("vertex needs 3 coordinates, got " + std::to_string(n));
      const Vec3 p{values[0], values[1], values[2]};
      check_finite(p, source, InputLocation::at_line(cur.line_number()));
      if (mesh.positions.size() >= UINT32_MAX) cur.fail("too many vertices");
      mesh.positions.push_back(p);
      if (n >= 6) {  // x y z r g b [a]: the common vertex-colour extension
        auto c = [](double v) {
          return static_cast<float>(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0));
        };
        colors.push_back({c(values[3]), c(values[4]), c(values[5])});
        ++colored;
      } else {
        colors.push_back({1, 1, 1});
      }
    } else if (kw == "f") {
      corners.clear();
      std::string_view tok;
      while (tokens.next(tok) && tok.front() != '#') {
        const std::string_view vtok = tok.substr(0, tok.find('/'));
        const std::int64_t i = cur.parse_int(vtok, "face vertex index");
        const auto count = static_cast<std::int64_t>(mesh.positions.size());
        std::int64_t resolved;
        if (i > 0) {
          resolved = i - 1;
          if (i > count) forward.push_back({i, cur.line_number()});
        } else if (i < 0) {
          resolved = count + i;
          if (resolved < 0)
            cur.fail("face vertex index " + std::to_string(i) + " is out of range (" + std::to_string(count) +
                     " vertices defined so far)");
        } else {
          cur.fail("face vertex index 0 is invalid (OBJ indices start at 1)");
        }
        if (resolved >= UINT32_MAX) cur.fail("face vertex index too large");
        corners.push_back(static_cast<std::uint32_t>(resolved));
      }
      if (corners.size() < 3)
        cur.fail("face needs at least 3 vertices, got " + std::to_string(corners.size()));
      ++out.polygons;
      for (std::size_t k = 1; k + 1 < corners.size(); ++k)
        mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
    }
    // vt, vn, vp, l, p, o, g, s, mtllib, usemtl and unknown statements: not geometry we print.
  }
  const auto count = static_cast<std::int64_t>(mesh.positions.size());
  for (const PendingIndex& p : forward) {
    if (p.index > count) {
      throw InputError(source, InputLocation::at_line(p.line),
                       "face vertex index " + std::to_string(p.index) + " is out of range (file has " +
                           std::to_string(count) + " vertices)");
    }
  }
  if (mesh.triangles.empty()) throw InputError(source, {}, "no faces in file");
  if (colored == mesh.positions.size()) mesh.colors = std::move(colors);
  return out;
}

}  // namespace salient::core::detail
