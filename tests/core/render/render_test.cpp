// Outputs people open elsewhere: the PLY we write reads back (with quality and colour), the PNG
// is a PNG of the right size, and the heat map runs blue to red.
#include <doctest/doctest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/common/input_error.hpp"
#include "core/mesh/mesh_reader.hpp"
#include "core/mesh/ply_writer.hpp"
#include "core/render/model_thumbnail.hpp"
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

TEST_CASE("a thumbnail shows the model shaded, fitted to any size, and its PNG reads back") {
  const Mesh box = salient::test::box(20, 12, 8);
  for (const auto& [w, h] : {std::pair{16, 16}, {220, 124}, {7, 40}}) {
    CAPTURE(w);
    const Image img = render_thumbnail(box, w, h);
    REQUIRE(img.width == w);
    REQUIRE(img.height == h);
    std::set<std::array<std::uint8_t, 3>> colours;
    int model = 0, x0 = w, x1 = -1, y0 = h, y1 = -1;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::uint8_t* p = img.rgb.data() + (static_cast<std::size_t>(y) * w + x) * 3;
        colours.insert({p[0], p[1], p[2]});
        if (p[0] == 255 && p[1] == 255 && p[2] == 255) continue;
        ++model, x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    // Fitted: it spans (nearly) the frame's width or its height, and leaves background around it.
    CHECK((x1 - x0 + 1 >= 0.8 * w || y1 - y0 + 1 >= 0.8 * h));
    CHECK(model < w * h);
    CHECK(colours.size() >= 3);  // three visible faces shaded apart, or two and the background
    const Image back = decode_png(png_bytes(img), "thumbnail");
    CHECK(back.width == w);
    CHECK(back.height == h);
    CHECK(back.rgb == img.rgb);
  }
  CHECK_THROWS_WITH_AS(decode_png("GIF89a....", "x.png"), "x.png: is not a PNG (bad signature)", InputError);
  const std::string png = png_bytes(Image(4, 4));
  CHECK_THROWS_AS(decode_png(png.substr(0, png.size() / 2), "x.png"), InputError);
}
