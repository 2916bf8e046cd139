// SlicingParams validation: every message names the setting to change.
#include "core/slicing/slicing_params.hpp"

#include <cmath>
#include <sstream>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool divides(double grid, double length) {
  const double q = length / grid;
  return std::fabs(q - std::round(q)) < 1e-6 * std::max(1.0, q);
}

}  // namespace

int SlicingParams::min_cells() const {
  return static_cast<int>(std::lround(min_layer / grid));
}
int SlicingParams::max_cells() const {
  return static_cast<int>(std::lround(max_layer / grid));
}

void validate(const SlicingParams& p) {
  if (!(std::isfinite(p.min_layer) && p.min_layer > 0))
    throw InputError(SettingId::min_layer,
                     "must be a positive number of millimetres, got " + fmt(p.min_layer));
  if (!(std::isfinite(p.max_layer) && p.max_layer > 0))
    throw InputError(SettingId::max_layer,
                     "must be a positive number of millimetres, got " + fmt(p.max_layer));
  if (p.min_layer > p.max_layer)
    throw InputError(SettingId::min_layer,
                     fmt(p.min_layer) + " mm is greater than {max_layer} " + fmt(p.max_layer) + " mm");
  if (!(std::isfinite(p.grid) && p.grid > 0))
    throw InputError(SettingId::grid, "must be a positive number of millimetres, got " + fmt(p.grid));
  if (!divides(p.grid, p.min_layer) || !divides(p.grid, p.max_layer))
    throw InputError(SettingId::grid, fmt(p.grid) + " mm does not divide {min_layer} " + fmt(p.min_layer) +
                                          " and {max_layer} " + fmt(p.max_layer));
  if (p.max_cells() > 4000)
    throw InputError(SettingId::grid,
                     fmt(p.grid) + " mm is too fine: {max_layer} would span more than 4000 cells");
}

void validate_rho(double rho) {
  if (!(rho >= 0 && rho <= 1)) throw InputError(SettingId::rho, "must be between 0 and 1, got " + fmt(rho));
}

}  // namespace salient::core
