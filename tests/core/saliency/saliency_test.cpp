// Saliency: range, determinism, invariance to rigid motion and uniform scale, bumps stand out
// on a sphere, small and large meshes, and the user's value files.
#include "core/saliency/saliency.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>

#include "core/common/input_error.hpp"
#include "core/mesh/mesh_loader.hpp"
#include "core/saliency/lee05_saliency.hpp"
#include "core/saliency/spectral_saliency.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

Mesh load(const char* file) {
  return load_mesh(std::filesystem::path(salient::test::model_path(file))).mesh;
}

double correlation(const std::vector<float>& a, const std::vector<float>& b) {
  const double n = static_cast<double>(a.size());
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n,
               mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// Rotated about an oblique axis, scaled by 37 and moved: the same surface to a viewer.
Mesh moved(Mesh m) {
  const double a = 0.7, c = std::cos(a), s = std::sin(a);
  for (Vec3& p : m.positions) {
    const Vec3 r{c * p.x - s * p.y, s * p.x + c * p.y, p.z};
    const Vec3 q{r.x, c * r.y - s * r.z, s * r.y + c * r.z};
    p = q * 37.0 + Vec3{120, -40, 9};
  }
  return m;
}

// A unit icosphere-like UV sphere with six sharp bumps; returns the bump tip vertices.
Mesh bumpy_sphere(std::vector<std::uint32_t>& tips) {
  Mesh m = salient::test::uv_sphere(48, 96);
  const Vec3 centres[] = {{1, 0, 0},  {-1, 0, 0},       {0, 1, 0},
                          {0, -1, 0}, {0.6, 0.6, 0.53}, {-0.6, -0.6, -0.53}};
  for (const Vec3& c0 : centres) {
    const Vec3 c = c0 / norm(c0);
    std::uint32_t tip = 0;
    double best = -2;
    for (std::uint32_t i = 0; i < m.positions.size(); ++i) {
      const double d = dot(m.positions[i], c);
      if (d > best) best = d, tip = i;
    }
    tips.push_back(tip);
    for (Vec3& p : m.positions) {
      const double ang = std::acos(std::clamp(dot(p / norm(p), c), -1.0, 1.0));
      if (ang < 0.25) p = p * (1 + 0.35 * (1 - ang / 0.25));  // a cone: sharp tip, sharp rim
    }
  }
  return m;
}

}  // namespace

TEST_CASE("saliency values are in [0, 1] and deterministic") {
  const Mesh m = load("spot.obj");
  for (SaliencyMethod method : {SaliencyMethod::spectral, SaliencyMethod::lee05}) {
    CAPTURE(saliency_method_name(method));
    const std::vector<float> a = compute_saliency(m, method, "spot.obj");
    const std::vector<float> b = compute_saliency(m, method, "spot.obj");
    REQUIRE(a.size() == m.vertex_count());
    CHECK(a == b);
    for (float v : a) REQUIRE((v >= 0 && v <= 1));
    CHECK(*std::max_element(a.begin(), a.end()) == 1.0f);
  }
}

TEST_CASE("saliency is invariant to rigid motion and uniform scale") {
  const Mesh m = load("spot.obj");
  for (SaliencyMethod method : {SaliencyMethod::spectral, SaliencyMethod::lee05}) {
    CAPTURE(saliency_method_name(method));
    const double r =
        correlation(compute_saliency(m, method, "spot"), compute_saliency(moved(m), method, "spot"));
    CAPTURE(r);
    CHECK(r >= 0.95);
  }
}

TEST_CASE("sharp bumps on a sphere are more salient than the smooth sphere") {
  std::vector<std::uint32_t> tips;
  const Mesh m = bumpy_sphere(tips);
  for (SaliencyMethod method : {SaliencyMethod::spectral, SaliencyMethod::lee05}) {
    CAPTURE(saliency_method_name(method));
    const std::vector<float> s = compute_saliency(m, method, "sphere");
    // Compare the bumps' neighbourhoods with the vertices far from every bump.
    double near_sum = 0, far_sum = 0;
    std::size_t near_n = 0, far_n = 0;
    for (std::uint32_t i = 0; i < m.vertex_count(); ++i) {
      double closest = 10;
      for (std::uint32_t t : tips)
        closest = std::min(
            closest, norm(m.positions[i] / norm(m.positions[i]) - m.positions[t] / norm(m.positions[t])));
      if (closest < 0.3) near_sum += s[i], ++near_n;
      if (closest > 0.7) far_sum += s[i], ++far_n;
    }
    const double near_mean = near_sum / near_n, far_mean = far_sum / far_n;
    CAPTURE(near_mean);
    CAPTURE(far_mean);
    CHECK(near_mean > 2 * far_mean);
  }
}

TEST_CASE("a 500-face and a 270k-face mesh both work") {
  const Mesh small = load("suzanne.obj");
  const Mesh large = load("igea.ply");
  CHECK(compute_saliency(small, SaliencyMethod::spectral, "suzanne").size() == small.vertex_count());
  CHECK(compute_saliency(small, SaliencyMethod::lee05, "suzanne").size() == small.vertex_count());
  CHECK(compute_saliency(large, SaliencyMethod::spectral, "igea").size() == large.vertex_count());
  CHECK(compute_saliency(large, SaliencyMethod::lee05, "igea").size() == large.vertex_count());
}

TEST_CASE("cancellation stops a saliency computation") {
  const Mesh m = load("spot.obj");
  CancelToken token;
  token.cancel();
  RunContext run{&token, {}};
  CHECK_THROWS_AS(compute_saliency(m, SaliencyMethod::spectral, "spot", run), Cancelled);
  CHECK_THROWS_AS(compute_saliency(m, SaliencyMethod::lee05, "spot", run), Cancelled);
}

TEST_CASE("a user's value file: read, and every problem named with its line") {
  const auto dir = std::filesystem::temp_directory_path();
  const auto write = [&](const char* name, const char* text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  CHECK(read_vertex_values(write("v3.txt", "# saliency\n0.5\n\n1\n0.25\n"), 3) ==
        std::vector<float>{0.5f, 1.0f, 0.25f});
  CHECK_THROWS_WITH_AS(read_vertex_values(write("bad.txt", "0.5\nhigh\n"), 3),
                       "bad.txt:2: expected a number for a vertex value, got 'high'", InputError);
  CHECK_THROWS_WITH_AS(read_vertex_values(write("short.txt", "0.5\n"), 3),
                       "short.txt: has 1 values, the model has 3 vertices", InputError);
  CHECK_THROWS_WITH_AS(read_vertex_values(write("long.txt", "1\n2\n3\n4\n"), 3),
                       "long.txt:4: more values than the model's 3 vertices", InputError);
}
