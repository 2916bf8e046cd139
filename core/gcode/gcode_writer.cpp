// write_gcode. Layers are written one by one into separate strings, the whole body is timed by
// estimate_gcode, and then each layer is prefixed with M73 (percent done, minutes left) from
// those times, and the header gets the totals.
#include "core/gcode/gcode_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/common/input_error.hpp"
#include "core/gcode/arc_fitter.hpp"
#include "core/gcode/time_estimator.hpp"

namespace salient::core {
namespace {

std::string fmt(const char* format, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

// A coordinate or E value with at most `decimals` decimals, trailing zeros dropped ("97.35",
// "0.01686", "-1"): every byte counts on a serial link.
std::string num(double a, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, a);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

// Replaces {key} placeholders of a profile's start/end G-code.
std::string fill_template(std::string text, const PrinterProfile& p) {
  const std::pair<const char*, double> values[] = {{"{extruder_temperature}", p.extruder_temperature},
                                                   {"{bed_temperature}", p.bed_temperature},
                                                   {"{bed_width}", p.bed_width},
                                                   {"{bed_depth}", p.bed_depth}};
  for (const auto& [key, value] : values) {
    const std::string v = fmt("%g", value);
    for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + v.size()))
      text.replace(at, std::string(key).size(), v);
  }
  if (!text.empty() && text.back() != '\n') text += '\n';
  return text;
}

// Part-cooling fan: Sailfish (MakerBot) has its own M-codes; Marlin and RepRap share M106/M107.
const char* fan_on(GcodeFlavor f) {
  return f == GcodeFlavor::sailfish ? "M126 T0" : "M106 S255";
}
const char* fan_off(GcodeFlavor f) {
  return f == GcodeFlavor::sailfish ? "M127 T0" : "M107";
}

class LayerWriter {
 public:
  LayerWriter(const PrinterProfile& p, const GcodeSettings& s, bool relative_e)
      : p_(p), s_(s), relative_e_(relative_e), arcs_(p.arc_fitting && p.flavor != GcodeFlavor::sailfish) {}

  std::string write(const LayerToolpaths& layer, std::size_t index) {
    out_.str("");
    const double h = layer.height();
    out_ << ";LAYER_CHANGE\n;Z:" << fmt("%.3f", layer.z_top) << "\n;HEIGHT:" << fmt("%.3f", h)
         << "\n;LAYER:" << index << "\n";
    if (static_cast<int>(index) == s_.fan_from_layer) out_ << fan_on(p_.flavor) << "\n";
    retract();
    out_ << "G1 Z" << fmt("%.3f", layer.z_top) << feed(p_.travel_speed) << "\n";
    // Minimum layer time: slow every extrusion of a quick layer down in proportion, to a floor (a
    // speck of a layer would otherwise be printed at ~0 mm/s, forever).
    double speed = index == 0 ? p_.first_layer_speed : p_.print_speed;
    double seconds = 0;
    for (const ExtrusionPath& path : layer.paths) seconds += path.length() / speed;
    if (seconds > 0 && seconds < s_.min_layer_time)
      speed = std::max(speed * seconds / s_.min_layer_time, std::min(speed, s_.min_print_speed));
    const double e_per_mm_area = 1.0 / (M_PI * p_.filament_diameter * p_.filament_diameter / 4);
    for (const ExtrusionPath& path : layer.paths) {
      if (path.points.empty()) continue;
      travel(path.points.front(), layer.region);
      unretract();
      const double e_per_mm = extrusion_area(path.width, path.height > 0 ? path.height : h) * e_per_mm_area;
      const std::size_t count = path.points.size() + (path.closed ? 1 : 0);
      if (arcs_ && count >= 3) {
        std::vector<Point2> points(path.points.begin(), path.points.end());
        if (path.closed) points.push_back(path.points.front());
        for (const PathMove& m : fit_arcs(points, p_.gcode_resolution)) {
          if (m.arc)
            extrude_arc(m, e_per_mm, speed);
          else
            extrude(m.to, e_per_mm, speed);
        }
        continue;
      }
      for (std::size_t k = 1; k < count; ++k) extrude(path.points[k % path.points.size()], e_per_mm, speed);
    }
    return out_.str();
  }

  double filament() const { return filament_; }

 private:
  // " F…" (mm/min) when the speed changes; G-code's feed rate is modal, so repeating it only
  // lengthens the line.
  std::string feed(double mm_per_s) {
    const std::string f = fmt("%.0f", mm_per_s * 60);
    if (f == feed_) return {};
    feed_ = f;
    return " F" + f;
  }
  void check(const Point2& p) const {
    const double x0 = p_.origin_at_center ? -p_.bed_width / 2 : 0,
                 y0 = p_.origin_at_center ? -p_.bed_depth / 2 : 0;
    if (p.x < x0 - 1e-6 || p.x > x0 + p_.bed_width + 1e-6 || p.y < y0 - 1e-6 ||
        p.y > y0 + p_.bed_depth + 1e-6)
      throw InputError("model", {},
                       "does not fit on the bed of " + p_.name + ": a path reaches (" + fmt("%.1f", p.x) +
                           ", " + fmt("%.1f", p.y) + ")");
  }
  // Combing: a travel that stays inside the part leaves any ooze where it is hidden, so only
  // travels that are long and cross the outline retract.
  void travel(const Point2& to, const Polygons& region) {
    check(to);
    const bool long_travel = std::hypot(to.x - at_.x, to.y - at_.y) > s_.retract_min_travel;
    if (!moved_ || (long_travel && !segment_inside(region, at_, to))) retract();
    out_ << "G0 X" << num(to.x, 3) << " Y" << num(to.y, 3) << feed(p_.travel_speed) << "\n";
    at_ = to;
    moved_ = true;
  }
  void extrude(const Point2& to, double e_per_mm, double speed) {
    check(to);
    const double e = std::hypot(to.x - at_.x, to.y - at_.y) * e_per_mm;
    filament_ += e;
    e_abs_ += e;
    out_ << "G1 X" << num(to.x, 3) << " Y" << num(to.y, 3) << " E" << num(relative_e_ ? e : e_abs_, 5)
         << feed(speed) << "\n";
    at_ = to;
  }
  // G2 (clockwise) / G3 (counter-clockwise) X Y I J E F, the centre relative to the start, as
  // Marlin's ARC_SUPPORT and RepRapFirmware read it; its E is for the arc's length.
  void extrude_arc(const PathMove& m, double e_per_mm, double speed) {
    check(m.to);
    const double e = m.length * e_per_mm;
    filament_ += e;
    e_abs_ += e;
    out_ << (m.ccw ? "G3 X" : "G2 X") << num(m.to.x, 3) << " Y" << num(m.to.y, 3) << " I"
         << num(m.center.x - at_.x, 3) << " J" << num(m.center.y - at_.y, 3) << " E"
         << num(relative_e_ ? e : e_abs_, 5) << feed(speed) << "\n";
    at_ = m.to;
  }
  void retract() {
    if (retracted_ || p_.retract_length <= 0) return;
    e_abs_ -= p_.retract_length;
    out_ << "G1 E" << num(relative_e_ ? -p_.retract_length : e_abs_, 5) << feed(p_.retract_speed) << "\n";
    retracted_ = true;
  }
  void unretract() {
    if (!retracted_) return;
    e_abs_ += p_.retract_length;
    out_ << "G1 E" << num(relative_e_ ? p_.retract_length : e_abs_, 5) << feed(p_.retract_speed) << "\n";
    retracted_ = false;
  }

  const PrinterProfile& p_;
  const GcodeSettings& s_;
  bool relative_e_;
  bool arcs_;  // never for Sailfish: s3g has no arcs (GPX skips G2/G3)
  std::ostringstream out_;
  Point2 at_{};
  bool moved_ = false, retracted_ = false;
  double e_abs_ = 0, filament_ = 0;
  std::string feed_;  // the last F written
};

// The comments PrusaSlicer writes and its G-code viewer, OctoPrint's and Moonraker's metadata
// readers take, in its words and number formats. With variable layers, "layer_height" is the mean
// above the first layer: what a reader needs to count the layers from the object's height.
void write_metadata(std::ostream& out, const std::vector<LayerToolpaths>& layers,
                    const PrinterProfile& printer, double seconds, double filament_mm) {
  out << "; layers = " << layers.size() << "\n";
  out << "; estimated printing time (normal mode) = " << time_dhms(seconds) << "\n";
  out << "; filament used [mm] = " << fmt("%.2f", filament_mm) << "\n";
  const double cm3 = filament_mm * M_PI * printer.filament_diameter * printer.filament_diameter / 4 / 1000;
  out << "; filament used [cm3] = " << fmt("%.2f", cm3) << "\n";
  if (layers.empty()) return;
  const double first = layers.front().height(), top = layers.back().z_top;
  const double mean =
      layers.size() > 1 ? (top - layers.front().z_top) / static_cast<double>(layers.size() - 1) : first;
  out << "; first_layer_height = " << num(first, 3) << "\n";
  out << "; layer_height = " << num(mean, 3) << "\n";
  out << "; max_layer_z = " << num(top, 3) << "\n";
}

}  // namespace

std::string time_dhms(double seconds) {
  const long total = std::lround(std::max(seconds, 0.0));
  const long d = total / 86400, h = total / 3600 % 24, m = total / 60 % 60, s = total % 60;
  char buf[64];
  if (d > 0)
    std::snprintf(buf, sizeof buf, "%ldd %ldh %ldm %lds", d, h, m, s);
  else if (h > 0)
    std::snprintf(buf, sizeof buf, "%ldh %ldm %lds", h, m, s);
  else if (m > 0)
    std::snprintf(buf, sizeof buf, "%ldm %lds", m, s);
  else
    std::snprintf(buf, sizeof buf, "%lds", s);
  return buf;
}

double extrusion_area(double w, double h) {
  if (h >= w) return M_PI * w * w / 4;
  return (w - h) * h + M_PI * h * h / 4;
}

GcodeResult write_gcode(const std::vector<LayerToolpaths>& layers, const PrinterProfile& printer,
                        const GcodeSettings& settings) {
  if (!layers.empty() && layers.back().z_top > printer.max_height + 1e-6)
    throw InputError("model", {},
                     "is " + fmt("%.1f", layers.back().z_top) + " mm tall, the " + printer.name +
                         " prints up to " + fmt("%.1f", printer.max_height) + " mm");
  const bool relative_e = settings.relative_e && printer.flavor != GcodeFlavor::sailfish;
  LayerWriter writer(printer, settings, relative_e);
  std::vector<std::string> bodies;
  bodies.reserve(layers.size());
  const RunContext run{settings.cancel, {}};
  for (std::size_t i = 0; i < layers.size(); ++i) {
    if (i % 32 == 0) run.check();
    bodies.push_back(writer.write(layers[i], i));
  }
  std::string body;
  for (const std::string& b : bodies) body += b;
  MachineLimits limits;
  limits.acceleration = limits.travel_acceleration = limits.retract_acceleration = printer.acceleration;
  limits.jerk[0] = limits.jerk[1] = printer.jerk;
  std::vector<CommandTiming> commands;
  const GcodeEstimate estimate = estimate_gcode((relative_e ? "M83\n" : "M82\n") + body, "generated", limits,
                                                &commands, settings.cancel);

  GcodeResult result;
  result.seconds = estimate.seconds;
  result.stream = stream_demand(commands, printer.baud);
  // The start code's prime line (and the end code's retraction) count too: the header says what
  // the whole file extrudes.
  const std::string start = fill_template(printer.start_gcode, printer),
                    end = fill_template(printer.end_gcode, printer);
  result.filament_mm = writer.filament() + estimate_gcode(start, "start_gcode", limits).filament_mm +
                       estimate_gcode(end, "end_gcode", limits).filament_mm;
  result.layers = layers.size();
  std::ostringstream out;
  out << "; generated by salient (saliency-preserving adaptive slicing)\n";
  // Where PrusaSlicer puts them: right after the first line, before any command.
  for (const GcodeThumbnail& t : settings.thumbnails) out << thumbnail_block(t);
  out << "; printer = " << printer.name << " (" << gcode_flavor_name(printer.flavor) << ")\n";
  for (const std::string& line : settings.summary) out << "; " << line << "\n";
  write_metadata(out, layers, printer, estimate.seconds, result.filament_mm);
  out << "\n";
  out << "M73 P0 R" << fmt("%.0f", std::ceil(estimate.seconds / 60)) << "\n";
  if (printer.flavor == GcodeFlavor::marlin) {
    // State the limits we planned with, so the firmware and every estimator use the same ones.
    out << "M201 X" << fmt("%.0f", limits.max_axis_acceleration[0]) << " Y"
        << fmt("%.0f", limits.max_axis_acceleration[1]) << " Z"
        << fmt("%.0f", limits.max_axis_acceleration[2]) << " E"
        << fmt("%.0f", limits.max_axis_acceleration[3]) << "\n";
    out << "M203 X" << fmt("%.0f", limits.max_feedrate[0]) << " Y" << fmt("%.0f", limits.max_feedrate[1])
        << " Z" << fmt("%.0f", limits.max_feedrate[2]) << " E" << fmt("%.0f", limits.max_feedrate[3]) << "\n";
    out << "M204 P" << fmt("%.0f", printer.acceleration) << " R" << fmt("%.0f", printer.acceleration) << " T"
        << fmt("%.0f", printer.acceleration) << "\n";
    out << "M205 X" << fmt("%.2f", printer.jerk) << " Y" << fmt("%.2f", printer.jerk) << " Z"
        << fmt("%.2f", limits.jerk[2]) << " E" << fmt("%.2f", limits.jerk[3]) << "\n";
  }
  out << start;
  out << (relative_e ? "M83\n" : "M82\n") << "G92 E0\n" << fan_off(printer.flavor) << "\n";
  double done = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const double percent = estimate.seconds > 0 ? 100 * done / estimate.seconds : 0;
    out << "M73 P" << fmt("%.0f", std::floor(percent)) << " R"
        << fmt("%.0f", std::ceil((estimate.seconds - done) / 60)) << "\n";
    out << bodies[i];
    if (i < estimate.layer_seconds.size()) done += estimate.layer_seconds[i];
  }
  out << "M73 P100 R0\n" << fan_off(printer.flavor) << "\n" << end;
  result.text = out.str();
  return result;
}

}  // namespace salient::core
