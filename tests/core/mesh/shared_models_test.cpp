// Every shared model loads with the face counts counted independently of our readers (a
// Python count of the files' `f` lines, facets and strips), and every invalid one is refused
// with a message that names the file and where.
#include <doctest/doctest.h>

#include <filesystem>
#include <regex>

#include "core/common/input_error.hpp"
#include "core/mesh/mesh_loader.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;
using salient::test::model_path;

namespace {

struct Expected {
  const char* file;
  MeshFormat format;
  std::size_t vertices_read;  // 0: not checked (STL corners are merged when read)
  std::size_t faces;
  std::size_t triangles;
};

const Expected expected[] = {
    {"stanford-bunny.obj", MeshFormat::obj, 35947, 69451, 69451},
    {"spot.obj", MeshFormat::obj, 2930, 5856, 5856},
    {"cow.obj", MeshFormat::obj, 2903, 5804, 5804},
    {"fandisk.obj", MeshFormat::obj, 6475, 12946, 12946},
    {"teapot.obj", MeshFormat::obj, 3644, 6320, 6320},
    {"suzanne.obj", MeshFormat::obj, 507, 500, 968},
    {"alligator.obj", MeshFormat::obj, 3208, 5981, 5981},
    {"beetle.obj", MeshFormat::obj, 1148, 2053, 2053},
    {"woody.obj", MeshFormat::obj, 694, 1267, 1267},
    {"igea.ply", MeshFormat::ply, 134345, 268686, 268686},
    {"cube_binary.ply", MeshFormat::ply, 8, 12, 12},
    {"float-color.ply", MeshFormat::ply, 3, 1, 1},
    {"Spider_binary.stl", MeshFormat::stl_binary, 0, 1368, 1368},
    {"sphereWithHole.stl", MeshFormat::stl_ascii, 0, 285, 285},
    {"triangle_with_two_solids.stl", MeshFormat::stl_ascii, 0, 2, 2},
};

}  // namespace

TEST_CASE("shared models load with the right counts") {
  for (const Expected& e : expected) {
    CAPTURE(e.file);
    const LoadedMesh m = load_mesh(std::filesystem::path(model_path(e.file)));
    CHECK(m.format == e.format);
    CHECK(m.polygons == e.faces);
    CHECK(m.triangles_read == e.triangles);
    if (e.vertices_read) CHECK(m.vertices_read == e.vertices_read);
    CHECK(m.mesh.triangle_count() > 0);
    CHECK(m.mesh.triangle_count() - m.repair.cap_faces <= e.triangles);  // caps: hole_filler_test.cpp
    for (const Triangle& t : m.mesh.triangles)
      for (std::uint32_t v : t) REQUIRE(v < m.mesh.vertex_count());
  }
}

TEST_CASE("closed shared models are watertight with outward volume") {
  for (const char* file : {"spot.obj", "cube_binary.ply", "fandisk.obj"}) {
    CAPTURE(file);
    const LoadedMesh m = load_mesh(std::filesystem::path(model_path(file)));
    CHECK(m.repair.watertight);
    CHECK(signed_volume(m.mesh) > 0);
  }
  const LoadedMesh teapot = load_mesh(std::filesystem::path(model_path("teapot.obj")));
  CHECK(teapot.repair.holes_filled > 0);  // its lid's and spout's openings, capped
  CHECK(teapot.repair.watertight);
  CHECK(signed_volume(teapot.mesh) > 0);
  const LoadedMesh holed = load_mesh(std::filesystem::path(model_path("sphereWithHole.stl")));
  CHECK_FALSE(holed.repair.watertight);
}

TEST_CASE("float vertex colours are read") {
  const LoadedMesh m = load_mesh(std::filesystem::path(model_path("float-color.ply")));
  REQUIRE(m.mesh.has_colors());
  CHECK(m.mesh.colors[0] == Color{0, 0, 1});
}

TEST_CASE("every invalid shared file is refused with its name and location") {
  // file -> what the message must say (and a line number where the problem has one)
  const std::pair<const char*, const char*> cases[] = {
      {"OutOfMemory.off",
       R"(^OutOfMemory\.off:2: header declares 353535235358 vertices and 6 faces, more than the remaining 288 bytes can hold$)"},
      {"empty.obj", R"(^empty\.obj: file is empty$)"},
      {"empty.off", R"(^empty\.off: file is empty$)"},
      {"empty.ply", R"(^empty\.ply: file is empty$)"},
      {"malformed.obj", R"(^malformed\.obj:[0-9]+: face vertex index (12|0) .*)"},
      {"malformed2.obj", R"(^malformed2\.obj:[0-9]+: face needs at least 3 vertices, got 0$)"},
  };
  for (const auto& [file, pattern] : cases) {
    CAPTURE(file);
    std::string message;
    try {
      load_mesh(std::filesystem::path(model_path(std::string("invalid/") + file)));
    } catch (const InputError& e) {
      message = e.what();
    }
    CAPTURE(message);
    CHECK(std::regex_search(message, std::regex(pattern)));
  }
}
