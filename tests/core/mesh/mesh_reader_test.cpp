// Mesh readers on inputs built in the test: every format's features and every kind of
// malformed input, each refused with the file and the line or byte where it goes wrong.
#include "core/mesh/mesh_reader.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/common/input_error.hpp"

using namespace salient::core;

namespace {

std::string error_of(const std::string& bytes, const std::string& name) {
  try {
    read_mesh(bytes, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

template <typename T>
void put(std::string& out, T value, bool big_endian = false) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  out.append(raw, sizeof(T));
}

std::string binary_stl(const std::string& header80, std::uint32_t count, int facets_written, float x0 = 0) {
  std::string out = header80;
  out.resize(80, ' ');
  put(out, count);
  for (int f = 0; f < facets_written; ++f) {
    for (int k = 0; k < 3; ++k) put(out, 0.0f);
    const float v[9] = {x0, 0, 0, 1, 0, static_cast<float>(f), 0, 1, 0};
    for (float c : v) put(out, c);
    put(out, std::uint16_t{0});
  }
  return out;
}

}  // namespace

TEST_CASE("binary STL whose header starts with 'solid' is read as binary") {
  const MeshFile f = read_mesh(binary_stl("solid exported by a CAD tool", 2, 2), "part.stl");
  CHECK(f.format == MeshFormat::stl_binary);
  CHECK(f.mesh.triangle_count() == 2);
  CHECK(f.mesh.vertex_count() == 4);  // shared corners merged
}

TEST_CASE("truncated binary STL names the byte offset") {
  const std::string bytes = binary_stl("binary", 1000, 3);
  CHECK(error_of(bytes, "part.stl") ==
        "part.stl: byte 80: file is truncated: header declares 1000 triangles (50084 bytes), file has 234 "
        "bytes");
}

TEST_CASE("binary STL with a NaN vertex is refused at that vertex") {
  const std::string bytes = binary_stl("x", 1, 1, std::numeric_limits<float>::quiet_NaN());
  CHECK(error_of(bytes, "nan.stl") ==
        "nan.stl: byte 96: vertex coordinate is not a finite number (NaN or infinity)");
}

TEST_CASE("ASCII STL with several solids, a missing final endsolid and CRLF") {
  const std::string text =
      "solid a\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n"
      "   vertex 0 1 0\r\n  endloop\r\n endfacet\r\nendsolid a\r\n"
      "solid b\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 1 1 0\n"
      " endloop\n endfacet\n";
  const MeshFile f = read_mesh(text, "two.stl");
  CHECK(f.format == MeshFormat::stl_ascii);
  CHECK(f.mesh.triangle_count() == 2);
  CHECK(f.mesh.vertex_count() == 4);
}

TEST_CASE("ASCII STL errors name the line") {
  const std::string text = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\n";
  CHECK(error_of(text, "bad.stl") == "bad.stl:5: expected a number for vertex y, got 'zero'");
  CHECK(error_of("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 inf\n", "inf.stl") ==
        "inf.stl:4: vertex coordinate is not a finite number (NaN or infinity)");
}

TEST_CASE("OBJ: polygons, negative indices, v/t/n corners and vertex colours") {
  const std::string text =
      "# a quad and a triangle\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\n"
      "vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//1 -2//1 -1//1\nusemtl none\n";
  const MeshFile f = read_mesh(text, "q.obj");
  CHECK(f.polygons == 2);
  REQUIRE(f.mesh.triangle_count() == 3);
  CHECK(f.mesh.triangles[0] == Triangle{0, 1, 2});
  CHECK(f.mesh.triangles[1] == Triangle{0, 2, 3});
  CHECK(f.mesh.triangles[2] == Triangle{0, 2, 3});
  REQUIRE(f.mesh.has_colors());
  CHECK(f.mesh.colors[1] == Color{0, 1, 0});
}

TEST_CASE("OBJ errors name the line") {
  CHECK(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "a.obj") ==
        "a.obj:4: face vertex index 4 is out of range (file has 3 vertices)");
  CHECK(error_of("v 0 0 0\nf -2 1 1\n", "b.obj") ==
        "b.obj:2: face vertex index -2 is out of range (1 vertices defined so far)");
  CHECK(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "c.obj") ==
        "c.obj:4: face vertex index 0 is invalid (OBJ indices start at 1)");
  CHECK(error_of("v 0 nan 0\n", "d.obj") ==
        "d.obj:1: vertex coordinate is not a finite number (NaN or infinity)");
  CHECK(error_of("v 1 2\n", "e.obj") == "e.obj:1: vertex needs 3 coordinates, got 2");
  CHECK(error_of("v 0 0 0\n", "f.obj") == "f.obj: no faces in file");
}

TEST_CASE("OFF: counts on the header line, comments, colours and polygons") {
  const std::string text =
      "COFF 4 1 0\n# comment\n0 0 0 255 0 0\n1 0 0 255 0 0\n1 1 0 0 0 255\n0 1 0 0 0 255\n4 0 1 2 3\n";
  const MeshFile f = read_mesh(text, "q.off");
  CHECK(f.format == MeshFormat::off);
  CHECK(f.mesh.triangle_count() == 2);
  REQUIRE(f.mesh.has_colors());
  CHECK(f.mesh.colors[3] == Color{0, 0, 1});
}

TEST_CASE("OFF errors name the line") {
  CHECK(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "a.off") ==
        "a.off:6: face vertex index 7 is out of range (3 vertices)");
  CHECK(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n", "b.off")
            .find("b.off:2: header declares 3 vertices and 1 faces") == 0);
  CHECK(error_of("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n0 0 0 0 0 0 0 0 0 0\n", "c.off") ==
        "c.off:6: face needs at least 3 vertices, declares 2");
}

namespace {

std::string ply_header(const std::string& format, int vertices, const std::string& extra_vertex_props,
                       const std::string& face_element) {
  return "ply\nformat " + format + " 1.0\ncomment test\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\n" + extra_vertex_props + face_element +
         "end_header\n";
}

}  // namespace

TEST_CASE("PLY ASCII with quality and colours") {
  const std::string text =
      ply_header("ascii", 3,
                 "property float quality\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n",
                 "element face 1\nproperty list uchar int vertex_indices\n") +
      "0 0 0 0.5 255 0 0\n1 0 0 1 0 255 0\n0 1 0 0 0 0 255\n3 0 1 2\n";
  const MeshFile f = read_mesh(text, "c.ply");
  CHECK(f.mesh.triangle_count() == 1);
  REQUIRE(f.mesh.has_quality());
  CHECK(f.mesh.quality[0] == doctest::Approx(0.5));
  REQUIRE(f.mesh.has_colors());
  CHECK(f.mesh.colors[1] == Color{0, 1, 0});
}

TEST_CASE("PLY binary big endian with tristrips and -1 restarts, and other elements skipped") {
  std::string bytes =
      ply_header("binary_big_endian", 5, "", "element tristrips 1\nproperty list int int vertex_indices\n");
  bytes.insert(bytes.find("end_header"), "element edge 1\nproperty int vertex1\nproperty int vertex2\n");
  const float v[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 2, 0};
  for (float c : v) put(bytes, c, true);
  const std::int32_t strip[] = {0, 1, 2, 3, -1, 2, 3, 4};
  put(bytes, std::int32_t{8}, true);
  for (std::int32_t i : strip) put(bytes, i, true);
  put(bytes, std::int32_t{0}, true);
  put(bytes, std::int32_t{1}, true);
  const MeshFile f = read_mesh(bytes, "s.ply");
  REQUIRE(f.mesh.triangle_count() == 3);
  CHECK(f.mesh.triangles[0] == Triangle{0, 1, 2});
  CHECK(f.mesh.triangles[1] == Triangle{2, 1, 3});  // odd strip triangles are reversed
  CHECK(f.mesh.triangles[2] == Triangle{2, 3, 4});
}

TEST_CASE("PLY errors: huge counts, bad indices, truncation, bad header") {
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  std::string huge = ply_header("binary_little_endian", 1, "", face);
  huge.replace(huge.find("vertex 1"), 8, "vertex 4000000000");
  CHECK(error_of(huge + std::string(64, '\0'), "h.ply")
            .find("h.ply:4: element 'vertex' declares 4000000000 entries") == 0);

  std::string bad_index = ply_header("binary_little_endian", 3, "", face);
  for (int i = 0; i < 9; ++i) put(bad_index, 0.0f);
  put(bad_index, std::uint8_t{3});
  put(bad_index, std::int32_t{0});
  put(bad_index, std::int32_t{1});
  put(bad_index, std::int32_t{9});
  const std::size_t index_at = bad_index.size() - 4;
  CHECK(error_of(bad_index, "i.ply") ==
        "i.ply: byte " + std::to_string(index_at + 4) + ": vertex index 9 is out of range (3 vertices)");

  std::string long_list =
      ply_header("binary_little_endian", 3, "", "element face 1\nproperty list int int vertex_indices\n");
  for (int i = 0; i < 9; ++i) put(long_list, 0.0f);
  put(long_list, std::int32_t{1000000000});
  CHECK(error_of(long_list, "l.ply").find("face list 'vertex_indices' declares 1000000000 items") !=
        std::string::npos);

  CHECK(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "t.ply") ==
        "t.ply:4: unexpected end of file in the header: no 'end_header'");
  CHECK(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n", "q.ply") ==
        "q.ply:4: unknown property type 'quaternion'");
  CHECK(error_of(ply_header("ascii", 3, "", face) + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "s.ply") ==
        "s.ply:14: unexpected end of file: expected a vertex index");
}

TEST_CASE("format comes from content before the extension") {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  CHECK(read_mesh(obj, "mislabelled.stl").format == MeshFormat::obj);
  CHECK(read_mesh("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "noext").format == MeshFormat::off);
  CHECK(error_of("hello world", "x.bin") ==
        "x.bin: unrecognised mesh format (expected STL, OBJ, PLY or OFF)");
  CHECK(error_of("", "x.stl") == "x.stl: file is empty");
}
