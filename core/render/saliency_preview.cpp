// render_preview: per view, project to 2D, rasterise triangles with barycentric interpolation
// of the value, keep the nearest fragment, shade by |n·view| so shape stays readable.
#include "core/render/saliency_preview.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/render/triangle_raster.hpp"

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
  DepthBuffer depth(x0, size, size);
  Vec3 dir{};
  if (view.depth == 0) dir = {view.depth_sign, 0, 0};
  if (view.depth == 1) dir = {0, view.depth_sign, 0};
  if (view.depth == 2) dir = {0, 0, view.depth_sign};
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    double X[3], Y[3], D[3];
    for (int k = 0; k < 3; ++k) project(mesh.positions[tri[k]], X[k], Y[k], D[k]);
    const double shade = 0.35 + 0.65 * std::fabs(dot(unit_normal(mesh, t), dir));
    raster_triangle(X, Y, D, depth, [&](int x, int y, double w0, double w1, double w2) {
      const float value = static_cast<float>(w0 * values[tri[0]] + w1 * values[tri[1]] + w2 * values[tri[2]]);
      const Color c = heat_color(value);
      std::uint8_t* pixel = img.at(x, y);
      pixel[0] = static_cast<std::uint8_t>(255 * c.r * shade);
      pixel[1] = static_cast<std::uint8_t>(255 * c.g * shade);
      pixel[2] = static_cast<std::uint8_t>(255 * c.b * shade);
    });
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
