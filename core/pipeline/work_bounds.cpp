// check_work_bounds: every message says which setting asks for too much and what would fit.
#include "core/pipeline/work_bounds.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

std::string mm(double v) {
  std::ostringstream s;
  s << v << " mm";
  return s.str();
}

// Names the setting that made the model this size (the height asked for, a scale, else the
// file itself) and what size that is: "height: 10000 mm makes the model 10000 mm tall, …".
[[noreturn]] void refuse(const MeshOptions& mesh, const std::string& size) {
  if (mesh.height) throw InputError(SettingId::height, mm(*mesh.height) + " makes the model " + size);
  if (mesh.scale != 1) {
    std::ostringstream s;
    s << mesh.scale;
    throw InputError(SettingId::scale, s.str() + " makes the model " + size);
  }
  throw InputError("model", {}, "is " + size);  // as ZProfile::build says it
}

}  // namespace

void check_work_bounds(const BoundingBox& placed, const MeshOptions& mesh, double min_layer, double grid,
                       const std::optional<BuildVolume>& volume) {
  const Vec3 size = placed.size();
  const double height = size.z;
  if (!std::isfinite(size.x) || !std::isfinite(size.y) || !std::isfinite(height))
    refuse(mesh, "larger than a number of millimetres can hold");
  if (height < min_layer) refuse(mesh, mm(height) + " tall, lower than {min_layer} " + mm(min_layer));
  if (volume) {
    if (height > volume->height + 1e-6)
      refuse(mesh, mm(height) + " tall, more than the printer's build volume " + mm(volume->height));
    if (size.x > volume->width + 1e-6 || size.y > volume->depth + 1e-6)
      refuse(mesh, mm(size.x) + " × " + mm(size.y) + " across, larger than the bed " + mm(volume->width) +
                       " × " + mm(volume->depth));
  }
  const double cells = height / grid;
  if (cells > kMaxPlanCells) {
    std::ostringstream s;
    s << grid << " mm cuts the model's " << height << " mm into " << std::llround(cells)
      << " planning cells, more than the " << kMaxPlanCells
      << " a slice may use; use a coarser {grid} or a smaller model";
    throw InputError(SettingId::grid, s.str());
  }
}

}  // namespace salient::core
