// Outputs people open elsewhere: the PLY we write reads back (with quality and colour), the PNG
// is a PNG of the right size, and the heat map runs blue to red.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "core/mesh/mesh_reader.hpp"
#include "core/mesh/ply_writer.hpp"
#include "core/render/saliency_preview.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

TEST_CASE("heat map runs from blue to red") {
  CHECK(heat_color(0) == Color{0, 0, 0.5f});
  CHECK(heat_color(1) == Color{0.5f, 0, 0});
  CHECK(heat_color(0.5f) == Color{0.5f, 1, 0.5f});
}

TEST_CASE("written PLY reads back with quality and colours") {
  const Mesh box = salient::test::box(1, 2, 3);
  std::vector<float> q(box.vertex_count());
  std::vector<Color> c(box.vertex_count());
  for (std::size_t i = 0; i < q.size(); ++i) q[i] = i / 7.0f, c[i] = heat_color(q[i]);
  const auto path = std::filesystem::temp_directory_path() / "salient_roundtrip.ply";
  write_ply(path, box, q, c);
  const MeshFile back = read_mesh_file(path);
  CHECK(back.mesh.triangles == box.triangles);
  CHECK(back.mesh.positions == box.positions);
  REQUIRE(back.mesh.has_quality());
  CHECK(back.mesh.quality[5] == doctest::Approx(5 / 7.0f));
  REQUIRE(back.mesh.has_colors());
  CHECK(back.mesh.colors[7].r == doctest::Approx(c[7].r).epsilon(0.01));
}

TEST_CASE("preview PNG has three views of the requested size") {
  const Mesh box = salient::test::box(1, 2, 3);
  const std::vector<float> v(box.vertex_count(), 0.5f);
  const Image img = render_preview(box, v, 64);
  CHECK(img.width == 192);
  CHECK(img.height == 64);
  int coloured = 0;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3)
    coloured += !(img.rgb[i] == 255 && img.rgb[i + 1] == 255);
  CHECK(coloured > 64 * 64 / 4);  // the box covers a good part of each view
  const auto path = std::filesystem::temp_directory_path() / "salient_preview.png";
  write_png(path, img);
  std::ifstream in(path, std::ios::binary);
  char sig[8];
  in.read(sig, 8);
  CHECK(std::string(sig, 8) == "\x89PNG\r\n\x1a\n");
}
