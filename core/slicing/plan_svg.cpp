// plan_svg: two panels sharing the height axis. Left: one bar per layer, its length the
// layer's thickness (α..ᾱ), coloured thin = red to thick = blue. Right: S[k] per cell.
#include "core/slicing/plan_svg.hpp"

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

std::string plan_svg(const Objective& objective, const LayerPlan& plan, const std::string& title,
                     const std::string& caption) {
  const ZProfile& p = objective.profile();
  const double W = 720, top = caption.empty() ? 40 : 58, bottom = 40, H = 520 + top,
               plot_h = H - top - bottom;
  const double left_x = 60, left_w = 300, right_x = 420, right_w = 260;
  const double a = p.params().min_layer, b = p.params().max_layer;
  auto y_of = [&](double z) { return top + plot_h * (1 - z / p.height()); };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 "
    << W << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << W / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << xml_escape(title)
    << "</text>\n";
  if (!caption.empty())
    s << "<text x=\"" << W / 2 << "\" y=\"38\" text-anchor=\"middle\" font-size=\"11\">"
      << xml_escape(caption) << "</text>\n";
  // Layers.
  for (const LayerReport& l : objective.layers(plan)) {
    const double t = b > a ? std::clamp((l.height - a) / (b - a), 0.0, 1.0) : 0.0;
    const int red = static_cast<int>(220 * (1 - t)), blue = static_cast<int>(220 * t);
    const double len = left_w * std::clamp(l.height / b, 0.0, 1.0);
    s << "<rect x=\"" << left_x << "\" y=\"" << num(y_of(l.z_top)) << "\" width=\"" << num(len)
      << "\" height=\"" << num(std::max(0.3, y_of(l.z_bottom) - y_of(l.z_top))) << "\" fill=\"rgb(" << red
      << ",60," << blue << ")\" stroke=\"white\" stroke-width=\"0.2\"/>\n";
  }
  // Saliency profile.
  const auto& S = p.channel(objective.geometric()).S;
  s << "<polyline fill=\"none\" stroke=\"black\" stroke-width=\"1\" points=\"";
  for (int k = 0; k < p.cells(); ++k)
    s << num(right_x + right_w * S[k]) << ',' << num(y_of(p.z(k) + 0.5 * p.grid())) << ' ';
  s << "\"/>\n";
  // Axes and labels.
  for (double x0 : {left_x, right_x}) {
    s << "<line x1=\"" << x0 << "\" y1=\"" << top << "\" x2=\"" << x0 << "\" y2=\"" << top + plot_h
      << "\" stroke=\"black\"/>\n";
  }
  s << "<line x1=\"" << left_x << "\" y1=\"" << top + plot_h << "\" x2=\"" << left_x + left_w << "\" y2=\""
    << top + plot_h << "\" stroke=\"black\"/>\n";
  s << "<line x1=\"" << right_x << "\" y1=\"" << top + plot_h << "\" x2=\"" << right_x + right_w << "\" y2=\""
    << top + plot_h << "\" stroke=\"black\"/>\n";
  s << "<text x=\"" << left_x + left_w / 2 << "\" y=\"" << H - 10
    << "\" text-anchor=\"middle\">layer thickness (mm, " << a << "–" << b << ")</text>\n";
  s << "<text x=\"" << right_x + right_w / 2 << "\" y=\"" << H - 10
    << "\" text-anchor=\"middle\">saliency S(z)</text>\n";
  s << "<text x=\"" << left_x + left_w << "\" y=\"" << top + plot_h + 14 << "\" text-anchor=\"end\">" << b
    << "</text>\n";
  s << "<text x=\"" << right_x + right_w << "\" y=\"" << top + plot_h + 14
    << "\" text-anchor=\"end\">1</text>\n";
  for (int i = 0; i <= 4; ++i) {
    const double z = p.height() * i / 4;
    s << "<text x=\"" << left_x - 6 << "\" y=\"" << num(y_of(z) + 4) << "\" text-anchor=\"end\">" << num(z)
      << "</text>\n";
  }
  s << "<text x=\"16\" y=\"" << top + plot_h / 2 << "\" transform=\"rotate(-90 16 " << top + plot_h / 2
    << ")\" text-anchor=\"middle\">height z (mm)</text>\n";
  s << "<text x=\"" << left_x + 4 << "\" y=\"" << top - 6 << "\">" << plan.layer_count()
    << " layers</text>\n";
  s << "</svg>\n";
  return s.str();
}

}  // namespace salient::core
