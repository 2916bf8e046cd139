// OFF reader: "[ST][C][N]OFF" header, counts (on the header line or the next), vertices
// "x y z [nx ny nz] [r g b [a]] [s t]", faces "n i0 … in-1 [colour]"; '#' comments.
// Counts are checked against the file's size before anything is reserved.
#include <cmath>

#include "core/mesh/format_readers.hpp"
#include "core/mesh/text_cursor.hpp"

namespace salient::core::detail {
namespace {

// Reads the next non-empty, non-comment line; false at the end of the file.
bool next_content_line(TextCursor& cur, std::string_view& line) {
  while (cur.next_line(line)) {
    const auto hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    if (line.find_first_not_of(" \t\r\f\v") != std::string_view::npos) return true;
  }
  return false;
}

// Smallest text an OFF vertex ("0 0 0\n") and triangle ("3 0 1 2\n") can take.
constexpr std::uint64_t min_vertex_bytes = 6;
constexpr std::uint64_t min_face_bytes = 8;

}  // namespace

MeshFile read_off(std::string_view bytes, const std::string& source) {
  TextCursor cur(bytes, source);
  std::string_view line;
  if (!next_content_line(cur, line)) cur.fail("file is empty");
  LineTokens header(line);
  std::string_view word;
  header.next(word);
  if (word.find('4') != std::string_view::npos || word.find('n') != std::string_view::npos)
    cur.fail("'" + std::string(word) + "': only 3-dimensional OFF is supported");
  const bool has_normals = word.find('N') != std::string_view::npos;
  const bool has_colors = word.find('C') != std::string_view::npos;
  std::string_view tok;
  std::int64_t counts[3] = {0, 0, 0};
  int n = 0;
  while (n < 3 && header.next(tok)) {
    if (tok == "BINARY") cur.fail("binary OFF is not supported; convert it to ASCII OFF, PLY or STL");
    counts[n++] = cur.parse_int(tok, "the vertex/face/edge counts");
  }
  if (n == 0) {
    if (!next_content_line(cur, line))
      cur.fail("unexpected end of file: expected the vertex and face counts");
    LineTokens count_tokens(line);
    while (n < 3 && count_tokens.next(tok)) counts[n++] = cur.parse_int(tok, "the vertex/face/edge counts");
  }
  if (n < 2) cur.fail("expected the vertex and face counts");
  const std::int64_t nv = counts[0], nf = counts[1];
  if (nv < 0 || nf < 0) cur.fail("negative vertex or face count");
  const auto room = static_cast<std::uint64_t>(cur.remaining());
  if (static_cast<std::uint64_t>(nv) > room / min_vertex_bytes ||
      static_cast<std::uint64_t>(nf) > room / min_face_bytes ||
      static_cast<std::uint64_t>(nv) * min_vertex_bytes + static_cast<std::uint64_t>(nf) * min_face_bytes >
          room) {
    cur.fail("header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
             " faces, more than the remaining " + std::to_string(room) + " bytes can hold");
  }
  MeshFile out{{}, MeshFormat::off, static_cast<std::size_t>(nf)};
  Mesh& mesh = out.mesh;
  mesh.positions.reserve(static_cast<std::size_t>(nv));
  std::vector<Color> colors;
  for (std::int64_t i = 0; i < nv; ++i) {
    if (!next_content_line(cur, line))
      cur.fail("unexpected end of file after " + std::to_string(i) + " of " + std::to_string(nv) +
               " vertices");
    LineTokens tokens(line);
    double values[12];
    int k = 0;
    while (k < 12 && tokens.next(tok)) values[k++] = cur.parse_double(tok, "vertex value");
    if (k < 3) cur.fail("vertex needs 3 coordinates, got " + std::to_string(k));
    const Vec3 p{values[0], values[1], values[2]};
    check_finite(p, source, InputLocation::at_line(cur.line_number()));
    mesh.positions.push_back(p);
    const int c0 = has_normals ? 6 : 3;
    if (has_colors && k >= c0 + 3) {
      const bool bytes_scale = values[c0] > 1 || values[c0 + 1] > 1 || values[c0 + 2] > 1;
      const double s = bytes_scale ? 1.0 / 255.0 : 1.0;
      colors.push_back({static_cast<float>(values[c0] * s), static_cast<float>(values[c0 + 1] * s),
                        static_cast<float>(values[c0 + 2] * s)});
    }
  }
  if (has_colors && colors.size() == mesh.positions.size()) mesh.colors = std::move(colors);
  mesh.triangles.reserve(static_cast<std::size_t>(nf));
  std::vector<std::uint32_t> corners;
  for (std::int64_t f = 0; f < nf; ++f) {
    if (!next_content_line(cur, line))
      cur.fail("unexpected end of file after " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    LineTokens tokens(line);
    if (!tokens.next(tok)) cur.fail("empty face line");
    const std::int64_t size = cur.parse_int(tok, "face vertex count");
    if (size < 3) cur.fail("face needs at least 3 vertices, declares " + std::to_string(size));
    if (static_cast<std::uint64_t>(size) > line.size())
      cur.fail("face declares " + std::to_string(size) + " vertices, line is too short");
    corners.clear();
    for (std::int64_t k = 0; k < size; ++k) {
      if (!tokens.next(tok))
        cur.fail("face declares " + std::to_string(size) + " vertices, lists " + std::to_string(k));
      const std::int64_t v = cur.parse_int(tok, "face vertex index");
      if (v < 0 || v >= nv)
        cur.fail("face vertex index " + std::to_string(v) + " is out of range (" + std::to_string(nv) +
                 " vertices)");
      corners.push_back(static_cast<std::uint32_t>(v));
    }
    for (std::size_t k = 1; k + 1 < corners.size(); ++k)
      mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
  }
  if (mesh.triangles.empty()) cur.fail("no faces in file");
  return out;
}

}  // namespace salient::core::detail
