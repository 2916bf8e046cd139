#include "core/segment/regions_svg.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "core/common/fixed_text.hpp"
#include "core/common/xml_escape.hpp"

namespace salient::core {
namespace {

std::string num(double v) {
  return fixed_text(v, 2);
}

}  // namespace

std::string regions_svg(const ZProfile& p, const std::vector<PlanRegion>& regions, const std::string& title) {
  const double W = 720, H = 560, top = 40, bottom = 40, plot_h = H - top - bottom;
  const double col_x[2] = {60, 400}, col_w = 280;
  const double a = p.params().min_layer, b = p.params().max_layer;
  auto y_of = [&](double z) { return top + plot_h * (1 - z / p.height()); };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 "
    << W << ' ' << H
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
       "fill=\"white\"/>\n";
  s << "<text x=\"" << W / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << xml_escape(title)
    << "</text>\n";
  int printed = 0;
  for (const PlanRegion& r : regions) {
    const double y0 = y_of(p.z(r.last_cell)), y1 = y_of(p.z(r.first_cell));
    if (r.side < 0)
      s << "<rect x=\"" << col_x[0] - 4 << "\" y=\"" << num(y0) << "\" width=\""
        << col_x[1] + col_w - col_x[0] + 8 << "\" height=\"" << num(y1 - y0) << "\" fill=\"#eeeeee\"/>\n";
    s << "<line x1=\"" << col_x[0] - 4 << "\" y1=\"" << num(y0) << "\" x2=\"" << col_x[1] + col_w
      << "\" y2=\"" << num(y0) << "\" stroke=\"gray\" stroke-dasharray=\"4 3\"/>\n";
    printed += r.layers();
    for (int i = 0; i < r.layers(); ++i) {
      const double zb = p.z(r.plan.boundaries[i]), zt = p.z(r.plan.boundaries[i + 1]), h = zt - zb;
      const double t = b > a ? std::clamp((h - a) / (b - a), 0.0, 1.0) : 0.0;
      const int red = static_cast<int>(220 * (1 - t)), blue = static_cast<int>(220 * t);
      // A part cut again takes its share of its side's column, by the sides it lies on.
      double share = 1, offset = 0;
      for (int sub : r.sub) share /= 2, offset += sub * share;
      const double len = share * col_w * std::clamp(h / b, 0.0, 1.0);
      for (int c = 0; c < 2; ++c) {
        if (r.side >= 0 && r.side != c) continue;
        s << "<rect x=\"" << num(col_x[c] + offset * col_w) << "\" y=\"" << num(y_of(zt)) << "\" width=\""
          << num(len) << "\" height=\"" << num(std::max(0.3, y_of(zb) - y_of(zt))) << "\" fill=\"rgb(" << red
          << ",60," << blue << ")\" stroke=\"white\" stroke-width=\"0.2\"/>\n";
      }
    }
  }
  for (int c = 0; c < 2; ++c) {
    s << "<line x1=\"" << col_x[c] << "\" y1=\"" << top << "\" x2=\"" << col_x[c] << "\" y2=\""
      << top + plot_h << "\" stroke=\"black\"/>\n";
    s << "<text x=\"" << col_x[c] + col_w / 2 << "\" y=\"" << H - 10 << "\" text-anchor=\"middle\">part " << c
      << ": layer thickness (mm, " << a << "–" << b << ")</text>\n";
  }
  for (int i = 0; i <= 4; ++i) {
    const double z = p.height() * i / 4;
    s << "<text x=\"" << col_x[0] - 6 << "\" y=\"" << num(y_of(z) + 4) << "\" text-anchor=\"end\">" << num(z)
      << "</text>\n";
  }
  s << "<text x=\"" << col_x[0] + 4 << "\" y=\"" << top - 6 << "\">" << regions.size() << " regions, "
    << printed << " layers in all (grey: both parts as one)</text>\n</svg>\n";
  return s.str();
}

}  // namespace salient::core
