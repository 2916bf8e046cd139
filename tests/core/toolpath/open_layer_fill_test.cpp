// Layers whose section is only open chains (a tear in the mesh wider than max_gap) take the
// outline common to the good layers around them, as PrusaSlicer's fix_slicing_errors does, so the
// model above is not printed on air; a tear taller than 1 mm is left empty (refused later).
#include <doctest/doctest.h>

#include "core/toolpath/toolpath_generator.hpp"

using namespace salient::core;

namespace {

// A 20 × 20 box, 10 mm tall, whose side at y = 0 is missing between z = tear_from and tear_to:
// sections there are one open chain with a 20 mm gap.
Mesh torn_box(double tear_from, double tear_to) {
  const double xy[4][2] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}}, z[4] = {0, tear_from, tear_to, 10};
  Mesh m;
  for (const auto& c : xy)
    for (double h : z) m.positions.push_back({c[0], c[1], h});
  const auto v = [](int corner, int level) { return static_cast<std::uint32_t>((corner % 4) * 4 + level); };
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) {
      if (c == 0 && k == 1) continue;  // the tear
      m.triangles.push_back({v(c, k), v(c + 1, k), v(c + 1, k + 1)});
      m.triangles.push_back({v(c, k), v(c + 1, k + 1), v(c, k + 1)});
    }
  m.triangles.push_back({v(0, 0), v(2, 0), v(1, 0)});  // bottom, facing down
  m.triangles.push_back({v(0, 0), v(3, 0), v(2, 0)});
  m.triangles.push_back({v(0, 3), v(1, 3), v(2, 3)});  // top
  m.triangles.push_back({v(0, 3), v(2, 3), v(3, 3)});
  return m;
}

std::vector<double> every(double step, double top) {
  std::vector<double> z;
  for (int i = 0; i * step <= top + 1e-9; ++i) z.push_back(i * step);
  return z;
}

}  // namespace

TEST_CASE("a layer of only open chains between good ones is filled from them, and marked") {
  ToolpathSettings s;
  const auto layers = generate_toolpaths(torn_box(5.0, 5.2), every(0.2, 10), s);
  std::size_t filled = 0;
  for (const LayerToolpaths& l : layers) {
    CHECK_FALSE(l.region.empty());  // every layer prints
    if (l.filled) {
      ++filled;
      CHECK(l.open_chains > 0);
      CHECK_FALSE(l.paths.empty());
    }
  }
  CHECK(filled == 1);  // the layer from 5.0 to 5.2 mm
}

TEST_CASE("a tear taller than a millimetre is left empty, not guessed") {
  ToolpathSettings s;
  const auto layers = generate_toolpaths(torn_box(3.0, 6.0), every(0.2, 10), s);
  std::size_t empty = 0;
  for (const LayerToolpaths& l : layers) {
    CHECK_FALSE(l.filled);
    empty += l.region.empty() ? 1 : 0;
  }
  CHECK(empty == 15);  // 3.0 to 6.0 mm
}
