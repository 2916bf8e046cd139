// render_thumbnail: rotate the model 45° about z and tilt it 30° toward the viewer (the usual
// three-quarter view), project orthographically, rasterise with a z-buffer and shade each face by
// Lambert's law with some ambient light so unlit faces keep their shape.
#include "core/render/model_thumbnail.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/render/triangle_raster.hpp"

namespace salient::core {
namespace {

// The camera's frame: screen right, screen up and the direction toward the viewer, in model
// coordinates (z up). Looking from azimuth −45° (front-right) and elevation 30°.
struct Camera {
  Vec3 right, up, toward;
};

Camera three_quarter_camera() {
  const double az = -M_PI / 4, el = M_PI / 6;
  const Vec3 toward{std::cos(el) * std::sin(-az), -std::cos(el) * std::cos(az), std::sin(el)};
  const Vec3 right = cross(Vec3{0, 0, 1}, toward) / norm(cross(Vec3{0, 0, 1}, toward));
  return {right, cross(toward, right), toward};
}

}  // namespace

Image render_thumbnail(const Mesh& mesh, int width, int height) {
  Image img(std::max(width, 1), std::max(height, 1));
  if (mesh.triangle_count() == 0) return img;
  const Camera cam = three_quarter_camera();
  // The projected extent fixes the scale: fit it in the image with a small margin.
  double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
  for (const Vec3& p : mesh.positions) {
    u0 = std::min(u0, dot(p, cam.right)), u1 = std::max(u1, dot(p, cam.right));
    v0 = std::min(v0, dot(p, cam.up)), v1 = std::max(v1, dot(p, cam.up));
  }
  const double scale =
      0.92 * std::min(img.width / std::max(u1 - u0, 1e-12), img.height / std::max(v1 - v0, 1e-12));
  const double cu = (u0 + u1) / 2, cv = (v0 + v1) / 2;
  const Vec3 light =
      (cam.toward + cam.up * 0.5 - cam.right * 0.4) / norm(cam.toward + cam.up * 0.5 - cam.right * 0.4);
  DepthBuffer depth(0, img.width, img.height);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    double X[3], Y[3], D[3];
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = mesh.positions[tri[k]];
      X[k] = img.width / 2.0 + (dot(p, cam.right) - cu) * scale;
      Y[k] = img.height / 2.0 - (dot(p, cam.up) - cv) * scale;
      D[k] = dot(p, cam.toward);
    }
    // Two-sided: meshes with flipped faces still read as solid.
    const double shade = 0.3 + 0.7 * std::fabs(dot(unit_normal(mesh, t), light));
    raster_triangle(X, Y, D, depth, [&](int x, int y, double, double, double) {
      std::uint8_t* pixel = img.at(x, y);
      pixel[0] = static_cast<std::uint8_t>(std::lround(237 * shade));
      pixel[1] = static_cast<std::uint8_t>(std::lround(107 * shade));
      pixel[2] = static_cast<std::uint8_t>(std::lround(33 * shade));
    });
  }
  return img;
}

}  // namespace salient::core
