// The work a slice may ask for (core/pipeline/work_bounds): settings inside their ranges that would
// take gigabytes, and a model thinner than a layer, are refused before saliency, naming the setting.
#include "core/pipeline/work_bounds.hpp"

#include <doctest/doctest.h>

#include <chrono>
#include <fstream>
#include <string>

#include "core/common/input_error.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/printer/printer_profile.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::core;

namespace {

// A tetrahedron `size` mm along each axis, as an OBJ file in `dir`.
std::string tetra_file(const std::filesystem::path& dir, const std::string& size) {
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "tetra.obj").string();
  std::ofstream(file) << "v 0 0 0\nv " << size << " 0 0\nv 0 " << size << " 0\nv 0 0 " << size
                      << "\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  return file;
}

// The setting slice_model refuses `settings` for (its key; "model" for the file), within seconds.
std::string refused_setting(SliceSettings settings) {
  const auto start = std::chrono::steady_clock::now();
  std::string key = "(sliced)";
  try {
    slice_model(settings, *builtin_printer("generic-i3"), {});
  } catch (const InputError& e) {
    key = e.setting() ? std::string(setting_key(*e.setting())) : e.source();
    MESSAGE(e.what());
  }
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(5));
  return key;
}

}  // namespace

TEST_CASE("settings that would ask for unbounded work are refused before saliency, naming the setting") {
  salient::test::ScratchDir dir("work-bounds");
  SliceSettings settings;
  settings.plan.mesh.model = tetra_file(dir.path, "10");
  settings.plan.saliency = SaliencyMethod::uniform;
  SUBCASE("scale 1e6: a 10 km model on a 200 mm bed") {
    settings.plan.mesh.scale = 1e6;
    CHECK(refused_setting(settings) == "scale");
  }
  SUBCASE("height 10000 mm: taller than the printer builds") {
    settings.plan.mesh.height = 10000;
    CHECK(refused_setting(settings) == "height");
  }
  SUBCASE("grid 0.001 mm on a 150 mm model: 150,000 planning cells") {
    settings.plan.mesh.height = 150;
    settings.plan.grid = 0.001;
    CHECK(refused_setting(settings) == "grid");
  }
}

TEST_CASE("a model 1e-20 mm across is refused as thinner than a layer, not a crash in saliency") {
  salient::test::ScratchDir dir("work-bounds-tiny");
  SliceSettings settings;
  settings.plan.mesh.model = tetra_file(dir.path, "1e-20");  // spectral saliency, the default
  CHECK(refused_setting(settings) == "model");
  settings.plan.mesh.scale = 1e-3;
  settings.plan.mesh.model = tetra_file(dir.path, "10");
  CHECK(refused_setting(settings) == "scale");
}

TEST_CASE(
    "check_work_bounds: what fits the printer and the cell budget passes, each limit names its setting") {
  const BuildVolume volume{220, 220, 250};
  const auto key = [&](const BoundingBox& box, const MeshOptions& mesh, double grid) -> std::string {
    try {
      check_work_bounds(box, mesh, 0.1, grid, volume);
    } catch (const InputError& e) {
      return e.setting() ? std::string(setting_key(*e.setting())) : e.source();
    }
    return "";
  };
  MeshOptions mesh;
  CHECK(key({{0, 0, 0}, {200, 200, 200}}, mesh, 0.01) == "");   // the shared models' sizes
  CHECK(key({{0, 0, 0}, {220, 220, 250}}, mesh, 0.005) == "");  // the whole volume, 50,000 cells
  CHECK(key({{0, 0, 0}, {221, 10, 10}}, mesh, 0.01) == "model");
  CHECK(key({{0, 0, 0}, {10, 10, 0.05}}, mesh, 0.01) == "model");
  mesh.height = 250;
  CHECK(key({{0, 0, 0}, {10, 10, 250}}, mesh, 0.001) == "grid");
  CHECK(key({{0, 0, 0}, {10, 10, 251}}, mesh, 0.01) == "height");
  try {
    MeshOptions tall;
    tall.height = 10000;
    check_work_bounds({{0, 0, 0}, {10, 10, 10000}}, tall, 0.1, 0.01, volume);
    FAIL("a model taller than the build volume is refused");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          "height: 10000 mm makes the model 10000 mm tall, more than the printer's build volume 250 mm");
  }
}
