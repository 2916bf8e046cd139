#include "protocol/marlin/resume_prelude.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <optional>
#include <string_view>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol::marlin {
namespace {

constexpr double kPrimeMm = 1.0;  // filament re-primed before going on

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.5g", v);
  return buf;
}

}  // namespace

std::vector<std::string> resume_prelude(const Program& program, std::size_t resume_from) {
  double hotend = 0, bed = 0, fan = 0, feed = 0;
  double pos[4] = {0, 0, 0, 0};
  bool relative = false, relative_e = false, inches = false;
  static constexpr char axes[4] = {'X', 'Y', 'Z', 'E'};
  for (std::size_t i = 0; i < std::min(resume_from, program.size()); ++i) {
    const std::string& c = program[i].text;
    const std::string_view code = std::string_view(c).substr(0, c.find(' '));
    if (code == "M104" || code == "M109")
      hotend = word_value(c, 'S').value_or(word_value(c, 'R').value_or(hotend));
    else if (code == "M140" || code == "M190")
      bed = word_value(c, 'S').value_or(word_value(c, 'R').value_or(bed));
    else if (code == "M106")
      fan = word_value(c, 'S').value_or(255);
    else if (code == "M107")
      fan = 0;
    else if (code == "G90")
      relative = false;
    else if (code == "G91")
      relative = true;
    else if (code == "M82")
      relative_e = false;
    else if (code == "M83")
      relative_e = true;
    else if (code == "G20")
      inches = true;
    else if (code == "G21")
      inches = false;
    else if (code == "G92") {
      for (int i = 0; i < 4; ++i)
        if (auto v = word_value(c, axes[i])) pos[i] = *v;
    } else if (code == "G28") {
      bool any = false;
      for (int i = 0; i < 3; ++i) any = any || word_value(c, axes[i]).has_value();
      for (int i = 0; i < 3; ++i)
        if (!any || word_value(c, axes[i])) pos[i] = 0;
    } else if (code == "G0" || code == "G1" || code == "G2" || code == "G3") {
      for (int i = 0; i < 4; ++i) {
        const auto v = word_value(c, axes[i]);
        if (!v) continue;
        const bool rel = i == 3 ? relative || relative_e : relative;
        pos[i] = rel ? pos[i] + *v : *v;
      }
      if (auto f = word_value(c, 'F')) feed = *f;
    }
  }
  std::vector<std::string> out;
  if (bed > 0) out.push_back("M140 S" + num(bed));
  if (hotend > 0) out.push_back("M104 S" + num(hotend));
  if (bed > 0) out.push_back("M190 S" + num(bed));
  if (hotend > 0) out.push_back("M109 S" + num(hotend));
  out.push_back(inches ? "G20" : "G21");
  out.push_back("G90");
  out.push_back(relative_e ? "M83" : "M82");
  out.push_back(fan > 0 ? "M106 S" + num(fan) : "M107");
  // Over the part first, then down onto it: never through it.
  out.push_back("G1 Z" + num(pos[2] + 1) + " F600");
  out.push_back("G1 X" + num(pos[0]) + " Y" + num(pos[1]) + " F6000");
  // Re-prime what oozed while the nozzle heated again, as the start code's prime line does, just
  // above where the print goes on; then the extruder counts from where the file left it.
  out.push_back("G92 E0");
  out.push_back("G1 E" + num(kPrimeMm) + " F300");
  out.push_back("G92 E" + num(pos[3]));
  out.push_back("G1 Z" + num(pos[2]) + " F600");
  if (feed > 0) out.push_back("G1 F" + num(feed));
  if (relative) out.push_back("G91");
  return out;
}

}  // namespace salient::protocol::marlin
