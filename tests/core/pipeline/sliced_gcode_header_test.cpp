// A sliced G-code's header as printers' screens, PrusaSlicer, OctoPrint and Moonraker read it:
// every thumbnail size of the profile, each a valid PNG of that size showing the model, before
// the first command; and the metadata comments in PrusaSlicer's words.
#include <doctest/doctest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "core/gcode/gcode_thumbnail.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/render/image.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::core;

namespace {

std::string off_text(const Mesh& m) {
  std::string s =
      "OFF\n" + std::to_string(m.vertex_count()) + " " + std::to_string(m.triangle_count()) + " 0\n";
  for (const Vec3& p : m.positions)
    s += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  for (const Triangle& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

SliceResult slice_box(const PrinterProfile& printer) {
  salient::test::ScratchDir dir("gcode-header");
  std::filesystem::create_directories(dir.path);
  const std::string file = (dir.path / "box.off").string();
  std::ofstream(file) << off_text(salient::test::box(20, 12, 8));
  SliceSettings settings;
  settings.plan.mesh.model = file;
  settings.toolpaths.infill_density = 0.1;
  return slice_model(settings, printer, {});
}

// Pixels that differ from the white background.
int model_pixels(const Image& img) {
  int n = 0;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3)
    n += img.rgb[i] != 255 || img.rgb[i + 1] != 255 || img.rgb[i + 2] != 255;
  return n;
}

}  // namespace

TEST_CASE("a sliced G-code carries the profile's thumbnails and PrusaSlicer's metadata") {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  REQUIRE(printer.thumbnails == std::vector<ThumbnailSize>{{16, 16}, {220, 124}});
  const SliceResult sliced = slice_box(printer);
  const std::vector<GcodeThumbnail> thumbnails = read_thumbnails(sliced.gcode, "sliced");
  REQUIRE(thumbnails.size() == printer.thumbnails.size());
  for (std::size_t i = 0; i < thumbnails.size(); ++i) {
    CAPTURE(i);
    CHECK(thumbnails[i].width == printer.thumbnails[i].width);
    CHECK(thumbnails[i].height == printer.thumbnails[i].height);
    const Image png = decode_png(thumbnails[i].png, "thumbnail");
    CHECK(png.width == printer.thumbnails[i].width);
    CHECK(png.height == printer.thumbnails[i].height);
    // The box fills a good part of the frame, and is not all one colour (it is shaded).
    CHECK(model_pixels(png) > png.width * png.height / 5);
    CHECK(model_pixels(png) < png.width * png.height);
  }
  // Before the first command: every line up to "; thumbnail end" is a comment.
  const std::size_t end = sliced.gcode.rfind("; thumbnail end");
  REQUIRE(end != std::string::npos);
  std::istringstream head(sliced.gcode.substr(0, end));
  for (std::string line; std::getline(head, line);) CHECK_MESSAGE(line.rfind(";", 0) == 0, line);

  const auto value = [&](const std::string& key) {
    std::smatch m;
    const std::regex re("\n; " + std::regex_replace(key, std::regex(R"([\[\]()])"), R"(\$&)") +
                        " = ([^\n]*)\n");
    REQUIRE_MESSAGE(std::regex_search(sliced.gcode, m, re), key);
    return m[1].str();
  };
  const long seconds = std::lround(sliced.print_seconds);
  std::ostringstream dhms;
  if (seconds >= 3600) dhms << seconds / 3600 << "h ";
  if (seconds >= 60) dhms << seconds / 60 % 60 << "m ";
  dhms << seconds % 60 << "s";
  CHECK(value("estimated printing time (normal mode)") == dhms.str());
  CHECK(std::stod(value("filament used [mm]")) == doctest::Approx(sliced.filament_mm).epsilon(1e-3));
  const double area = M_PI * printer.filament_diameter * printer.filament_diameter / 4;
  CHECK(std::stod(value("filament used [cm3]")) ==
        doctest::Approx(sliced.filament_mm * area / 1000).epsilon(1e-2));
  CHECK(std::stod(value("first_layer_height")) == doctest::Approx(sliced.z.front()));
  CHECK(std::stod(value("max_layer_z")) == doctest::Approx(8));
  const double mean = (sliced.z.back() - sliced.z.front()) / (sliced.z.size() - 1);
  CHECK(std::stod(value("layer_height")) == doctest::Approx(mean).epsilon(1e-2));
}

TEST_CASE("a profile without thumbnails writes none") {
  PrinterProfile printer = *builtin_printer("generic-i3");
  printer.thumbnails.clear();
  CHECK(read_thumbnails(slice_box(printer).gcode, "sliced").empty());
}
