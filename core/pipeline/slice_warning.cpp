// The size checks: a model read in the wrong units ends as a one- or two-layer job or one that
// leaves the bed, and nothing in the G-code says why; these say it, with the fix.
#include "core/pipeline/slice_warning.hpp"

#include <algorithm>
#include <cstdio>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

// Every side under this (mm): no printable figure is that small; a file in metres or of unit
// size is (a 15 cm bunny in metres is 0.15 mm).
constexpr double tiny_mm = 5;

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, v < 10 ? "%.2g" : "%.0f", v);
  return buf;
}

std::string size_text(const Vec3& s) {
  return mm(s.x) + " × " + mm(s.y) + " × " + mm(s.z) + " mm";
}

// A round factor a little under the one that fits `size` in the build volume.
std::string fitting_scale(const Vec3& size, const PrinterProfile& printer) {
  const double fit =
      std::min({printer.bed_width / size.x, printer.bed_depth / size.y, printer.max_height / size.z});
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", fit * 0.9);
  return buf;
}

}  // namespace

std::vector<SliceWarning> model_size_warnings(const BoundingBox& placed, const PrinterProfile& printer,
                                              const std::string& model_name) {
  std::vector<SliceWarning> out;
  const Vec3 s = placed.size();
  if (std::max({s.x, s.y, s.z}) < tiny_mm) {
    const bool metres_fit = s.x * 1000 <= printer.bed_width && s.y * 1000 <= printer.bed_depth &&
                            s.z * 1000 <= printer.max_height;
    out.push_back({"model_tiny", model_name + " is " + mm(s.z) + " mm tall as placed (" + size_text(s) +
                                     "): its file is likely in metres or of unit size, read as millimetres. "
                                     "Give {height} in millimetres (e.g. 80)" +
                                     (metres_fit ? ", or {scale} 1000 if it is in metres" : "")});
  }
  if (s.x > printer.bed_width + 1e-6 || s.y > printer.bed_depth + 1e-6 || s.z > printer.max_height + 1e-6)
    out.push_back({"model_larger_than_bed",
                   model_name + " is " + size_text(s) + " as placed, larger than " + printer.name + "'s " +
                       size_text({printer.bed_width, printer.bed_depth, printer.max_height}) +
                       " build volume: its file may be in other units than millimetres. Give {height} in "
                       "millimetres, or {scale} " +
                       fitting_scale(s, printer) + " to fit it"});
  return out;
}

void check_printable_height(const BoundingBox& placed, double first_layer, const std::string& model_name) {
  const double h = placed.size().z;
  if (h >= first_layer) return;
  throw InputError(model_name, {},
                   "the model is " + mm(h) + " mm tall as placed, less than one first layer (" +
                       mm(first_layer) +
                       " mm): nothing of it would print. Its file is likely in metres or of unit size: give "
                       "{height} in millimetres (e.g. 80) or a {scale} (1000 from metres, 25.4 from inches)");
}

}  // namespace salient::core
