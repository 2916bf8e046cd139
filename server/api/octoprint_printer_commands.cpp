#include "server/api/octoprint_printer_commands.hpp"

#include <cmath>
#include <cstdio>

#include "server/http/router.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

[[noreturn]] void bad(const std::string& message) {
  throw ApiError(400, "bad_request", message);
}

double number(const json& v, const std::string& what) {
  if (!v.is_number()) bad(what + " must be a number, got " + v.dump().substr(0, 40));
  const double d = v.get<double>();
  if (!std::isfinite(d)) bad(what + " must be a finite number");
  return d;
}

// "12.5", "210", "-0.1": at most three decimals, no trailing zeros.
std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  std::string s = buf;
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

double temperature(const json& v, const std::string& what, double max) {
  const double t = number(v, what);
  if (t < 0 || t > max) bad(what + " must be 0 to " + fmt(max) + " °C, got " + fmt(t));
  return t;
}

// OctoPrint's factors: an integer is a percentage, a fraction a ratio.
int percent(const json& v, const std::string& what, int lo, int hi) {
  const double raw = number(v, what);
  const double p = v.is_number_float() && raw <= 10 ? raw * 100 : raw;
  if (p < lo || p > hi)
    bad(what + " must be " + std::to_string(lo) + " to " + std::to_string(hi) + " % (or " + fmt(lo / 100.0) +
        " to " + fmt(hi / 100.0) + "), got " + fmt(raw));
  return static_cast<int>(std::lround(p));
}

}  // namespace

std::vector<std::string> tool_target_gcode(const json& targets, double offset) {
  if (!targets.is_object() || targets.empty()) bad("'targets' must be an object such as {\"tool0\": 210}");
  std::vector<std::string> out;
  for (const auto& [tool, value] : targets.items()) {
    if (tool != "tool0") bad("'targets' names " + tool.substr(0, 40) + ": this printer has one tool, tool0");
    double t = temperature(value, "the target of tool0", kMaxToolTemperature);
    if (t > 0) t = std::min(std::max(t + offset, 0.0), kMaxToolTemperature);
    out.push_back("M104 S" + fmt(t));
  }
  return out;
}

std::vector<std::string> bed_target_gcode(const json& target, double offset) {
  double t = temperature(target, "the bed's target", kMaxBedTemperature);
  if (t > 0) t = std::min(std::max(t + offset, 0.0), kMaxBedTemperature);
  return {"M140 S" + fmt(t)};
}

double checked_offset(const json& value, const std::string& what) {
  const double o = number(value, "the offset of " + what);
  if (std::abs(o) > kMaxOffset) bad("the offset of " + what + " must be -50 to 50 °C, got " + fmt(o));
  return o;
}

std::vector<std::string> tool_select_gcode(const json& tool) {
  if (!tool.is_string() || tool.get<std::string>() != "tool0")
    bad("'tool' must be \"tool0\": this printer has one tool");
  return {"T0"};
}

std::vector<std::string> extrude_gcode(const json& body) {
  const double amount = number(body.value("amount", json()), "'amount'");
  if (std::abs(amount) > kMaxExtrudeMm)
    bad("'amount' must be within ±" + fmt(kMaxExtrudeMm) + " mm, got " + fmt(amount));
  double speed = 300;  // mm/min, OctoPrint's default extrusion speed
  if (const auto s = body.find("speed"); s != body.end() && !s->is_null() && !s->is_boolean()) {
    speed = number(*s, "'speed'");
    if (speed <= 0 || speed > kMaxFeedMmPerMin) bad("'speed' must be above 0 and at most 60000 mm/min");
  }
  return {"G91", "M83", "G1 E" + fmt(amount) + " F" + fmt(speed), "M82", "G90"};
}

std::string flowrate_gcode(const json& factor) {
  return "M221 S" + std::to_string(percent(factor, "'factor'", 75, 125));
}

std::string feedrate_gcode(const json& factor) {
  return "M220 S" + std::to_string(percent(factor, "'factor'", 50, 200));
}

std::vector<std::string> jog_gcode(const json& body, const core::PrinterProfile& profile) {
  const bool absolute = body.value("absolute", json(false)) == json(true);
  const double size[3] = {profile.bed_width, profile.bed_depth, profile.max_height};
  const double lo[3] = {profile.origin_at_center ? -size[0] / 2 : 0,
                        profile.origin_at_center ? -size[1] / 2 : 0, 0};
  std::string move = "G1";
  bool any = false, z_only = true;
  for (int i = 0; i < 3; ++i) {
    const std::string axis(1, "xyz"[i]);
    const auto v = body.find(axis);
    if (v == body.end()) continue;
    const double d = number(*v, "'" + axis + "'");
    if (absolute && (d < lo[i] || d > lo[i] + size[i]))
      bad("'" + axis + "' = " + fmt(d) + " is outside the printer's volume (" + fmt(lo[i]) + " to " +
          fmt(lo[i] + size[i]) + " mm)");
    if (!absolute && std::abs(d) > size[i])
      bad("'" + axis + "' = " + fmt(d) + " mm is a longer move than the printer's " + fmt(size[i]) + " mm");
    any = true;
    if (!absolute && d == 0) continue;  // FDM Monster sends all three axes, 0 for those that stay
    move += ' ';
    move += "XYZ"[i];
    move += fmt(d);
    z_only = z_only && i == 2;
  }
  if (!any) bad("a jog needs at least one of 'x', 'y', 'z' (mm)");
  if (move == "G1") return {};         // nothing moves
  double speed = z_only ? 200 : 6000;  // mm/min: OctoPrint's default movement speeds
  if (const auto s = body.find("speed"); s != body.end() && !s->is_null() && !s->is_boolean()) {
    speed = number(*s, "'speed'");
    if (speed <= 0 || speed > kMaxFeedMmPerMin) bad("'speed' must be above 0 and at most 60000 mm/min");
  }
  move += " F" + fmt(speed);
  if (absolute) return {"G90", move};
  return {"G91", move, "G90"};
}

std::vector<std::string> home_gcode(const json& body) {
  const auto axes = body.find("axes");
  if (axes == body.end() || !axes->is_array() || axes->empty())
    bad("'axes' must be a list of axes to home, such as [\"x\", \"y\", \"z\"]");
  std::string out = "G28";
  for (const json& a : *axes) {
    if (!a.is_string() || (a != "x" && a != "y" && a != "z"))
      bad("'axes' may hold \"x\", \"y\" and \"z\" only, got " + a.dump().substr(0, 40));
    const std::string axis = a.get<std::string>();
    const std::string word = std::string(1, static_cast<char>(std::toupper(axis[0]))) + "0";
    if (out.find(" " + word) == std::string::npos) out += " " + word;
  }
  return {out};
}

}  // namespace salient::server
