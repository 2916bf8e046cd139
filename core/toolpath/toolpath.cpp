// ExtrusionPath measures.
#include "core/toolpath/toolpath.hpp"

#include <cmath>

namespace salient::core {

double ExtrusionPath::length() const {
  double total = 0;
  for (std::size_t i = 1; i < points.size(); ++i)
    total += std::hypot(points[i].x - points[i - 1].x, points[i].y - points[i - 1].y);
  if (closed && points.size() > 2)
    total += std::hypot(points.front().x - points.back().x, points.front().y - points.back().y);
  return total;
}

}  // namespace salient::core
