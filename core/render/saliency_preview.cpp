// render_preview: per view, project to 2D, rasterise triangles with barycentric interpolation
// of the value, keep the nearest fragment, shade by |n·view| so shape stays readable.
#include "core/render/saliency_preview.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace salient::core {

Color heat_color(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  const float r = std::clamp(1.5f - std::fabs(4 * v - 3), 0.0f, 1.0f);
  const float g = std::clamp(1.5f - std::fabs(4 * v - 2), 0.0f, 1.0f);
  const float b = std::clamp(1.5f - std::fabs(4 * v - 1), 0.0f, 1.0f);
  return {r, g, b};
}

namespace {

struct View {
  int u, v, depth;    // axes for screen x, screen y (up), and depth (toward the viewer)
  double depth_sign;  // +1: larger coordinate is nearer
  double u_sign;
};

void draw_view(const Mesh& mesh, std::span<const float> values, Image& img, int x0, int size,
               const View& view) {
  const BoundingBox box = bounding_box(mesh);
  const double su = box.size()[view.u], sv = box.size()[view.v];
  const double scale = 0.9 * size / std::max({su, sv, 1e-12});
  auto project = [&](const Vec3& p, double& x, double& y, double& d) {
    x = x0 + size / 2.0 + view.u_sign * (p[view.u] - box.center()[view.u]) * scale;
    y = size / 2.0 - (p[view.v] - box.center()[view.v]) * scale;
    d = view.depth_sign * p[view.depth];
  };
  std::vector<double> zbuf(static_cast<std::size_t>(size) * size, -std::numeric_limits<double>::infinity());
  Vec3 dir{};
  if (view.depth == 0) dir = {view.depth_sign, 0, 0};
  if (view.depth == 1) dir = {0, view.depth_sign, 0};
  if (view.depth == 2) dir = {0, 0, view.depth_sign};
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    double X[3], Y[3], D[3];
    for (int k = 0; k < 3; ++k) project(mesh.positions[tri[k]], X[k], Y[k], D[k]);
    const double area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    if (std::fabs(area) < 1e-12) continue;
    const double shade = 0.35 + 0.65 * std::fabs(dot(unit_normal(mesh, t), dir));
    const int xmin = std::max(x0, static_cast<int>(std::floor(std::min({X[0], X[1], X[2]}))));
    const int xmax = std::min(x0 + size - 1, static_cast<int>(std::ceil(std::max({X[0], X[1], X[2]}))));
    const int ymin = std::max(0, static_cast<int>(std::floor(std::min({Y[0], Y[1], Y[2]}))));
    const int ymax = std::min(size - 1, static_cast<int>(std::ceil(std::max({Y[0], Y[1], Y[2]}))));
    for (int y = ymin; y <= ymax; ++y)
      for (int x = xmin; x <= xmax; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((X[1] - px) * (Y[2] - py) - (X[2] - px) * (Y[1] - py)) / area;
        const double w1 = ((X[2] - px) * (Y[0] - py) - (X[0] - px) * (Y[2] - py)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double d = w0 * D[0] + w1 * D[1] + w2 * D[2];
        double& z = zbuf[static_cast<std::size_t>(y) * size + (x - x0)];
        if (d <= z) continue;
        z = d;
        const float value =
            static_cast<float>(w0 * values[tri[0]] + w1 * values[tri[1]] + w2 * values[tri[2]]);
        const Color c = heat_color(value);
        std::uint8_t* pixel = img.at(x, y);
        pixel[0] = static_cast<std::uint8_t>(255 * c.r * shade);
        pixel[1] = static_cast<std::uint8_t>(255 * c.g * shade);
        pixel[2] = static_cast<std::uint8_t>(255 * c.b * shade);
      }
  }
}

}  // namespace

Image render_preview(const Mesh& mesh, std::span<const float> values, int view_size) {
  Image img(3 * view_size, view_size);
  draw_view(mesh, values, img, 0, view_size, {0, 2, 1, -1, 1});             // front: looking along +y
  draw_view(mesh, values, img, view_size, view_size, {1, 2, 0, 1, 1});      // side: from +x
  draw_view(mesh, values, img, 2 * view_size, view_size, {0, 1, 2, 1, 1});  // top: from +z
  return img;
}

}  // namespace salient::core
