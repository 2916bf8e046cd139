// raster_triangle: the z-buffered scan conversion both renderers (saliency previews, G-code
// thumbnails) share; what each pixel becomes is the caller's.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace salient::core {

// Depths over the pixel columns x0 .. x0 + width − 1 and rows 0 .. height − 1 of an image; larger
// is nearer the viewer.
struct DepthBuffer {
  int x0, width, height;
  std::vector<double> depth;
  DepthBuffer(int x0_, int width_, int height_)
      : x0(x0_),
        width(width_),
        height(height_),
        depth(static_cast<std::size_t>(width_) * height_, -std::numeric_limits<double>::infinity()) {}
};

// Calls plot(x, y, w0, w1, w2) for each pixel whose centre lies in the projected triangle (X, Y
// in pixels, D the depth of each corner) and is nearer than what `buffer` holds there, after
// recording its depth; w are the pixel's barycentric weights. Zero-area triangles draw nothing.
template <typename Plot>
void raster_triangle(const double (&X)[3], const double (&Y)[3], const double (&D)[3], DepthBuffer& buffer,
                     Plot&& plot) {
  const double area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  if (std::fabs(area) < 1e-12) return;
  const int xmin = std::max(buffer.x0, static_cast<int>(std::floor(std::min({X[0], X[1], X[2]}))));
  const int xmax =
      std::min(buffer.x0 + buffer.width - 1, static_cast<int>(std::ceil(std::max({X[0], X[1], X[2]}))));
  const int ymin = std::max(0, static_cast<int>(std::floor(std::min({Y[0], Y[1], Y[2]}))));
  const int ymax = std::min(buffer.height - 1, static_cast<int>(std::ceil(std::max({Y[0], Y[1], Y[2]}))));
  for (int y = ymin; y <= ymax; ++y)
    for (int x = xmin; x <= xmax; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      const double w0 = ((X[1] - px) * (Y[2] - py) - (X[2] - px) * (Y[1] - py)) / area;
      const double w1 = ((X[2] - px) * (Y[0] - py) - (X[0] - px) * (Y[2] - py)) / area;
      const double w2 = 1 - w0 - w1;
      if (w0 < 0 || w1 < 0 || w2 < 0) continue;
      const double d = w0 * D[0] + w1 * D[1] + w2 * D[2];
      double& z = buffer.depth[static_cast<std::size_t>(y) * buffer.width + (x - buffer.x0)];
      if (d <= z) continue;
      z = d;
      plot(x, y, w0, w1, w2);
    }
}

}  // namespace salient::core
