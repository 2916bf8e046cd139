// parse_plan_file: one reader per format; each reports the line (or entry) a problem is on.
#include "core/export/plan_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <optional>

#include "core/common/input_error.hpp"
#include "core/export/plan_json.hpp"
#include "core/export/zip_reader.hpp"
#include "core/gcode/gcode_line.hpp"

namespace salient::core {
namespace {

constexpr std::string_view prusa_profile_entry = "Metadata/Slic3r_PE_layer_heights_profile.txt";

std::optional<double> number_at(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end == text.data() || !std::isfinite(v)) return std::nullopt;
  return v;
}

void add_top(PlanFile& out, double z, std::uint64_t line, const std::string& name) {
  if (!(z > 0))
    throw InputError(name, InputLocation::at_line(line),
                     "layer top " + std::to_string(z) + " mm is not above the bed");
  if (!out.tops.empty() && !(z > out.tops.back() + 1e-9))
    throw InputError(name, InputLocation::at_line(line),
                     "layer top " + std::to_string(z) + " mm is not above the previous layer's " +
                         std::to_string(out.tops.back()) + " mm (Z must rise layer by layer)");
  out.tops.push_back(z);
  out.lines.push_back(line);
}

template <typename F>
void for_each_line(std::string_view text, F&& f) {
  std::uint64_t n = 0;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    std::string_view line = text.substr(0, eol);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    f(line, ++n);
    if (eol == std::string_view::npos) break;
    text.remove_prefix(eol + 1);
  }
}

// PrusaSlicer and salient: ";Z:<top>" after each ";LAYER_CHANGE".
PlanFile gcode_z_comments(std::string_view text, const std::string& name) {
  PlanFile out{"G-code (;Z: comments)", {}, {}};
  for_each_line(text, [&](std::string_view line, std::uint64_t n) {
    if (!line.starts_with(";Z:")) return;
    const auto z = number_at(line.substr(3));
    if (!z) throw InputError(name, InputLocation::at_line(n), "malformed ;Z: comment");
    add_top(out, *z, n, name);
  });
  return out;
}

// Cura: ";LAYER:n" (negative n: raft), and the layer's height is the Z of its first extrusion —
// Cura moves to the next layer's Z before it writes the next ";LAYER:" line.
PlanFile gcode_cura_layers(std::string_view text, const std::string& name) {
  PlanFile out{"G-code (;LAYER: and extrusion Z)", {}, {}};
  bool relative_e = false, in_layer = false, seen = false;
  double z = 0, e = 0;
  for_each_line(text, [&](std::string_view line, std::uint64_t n) {
    if (line.starts_with(";LAYER:")) {
      const auto index = number_at(line.substr(7));
      in_layer = index && *index >= 0;
      seen = false;
      return;
    }
    if (line.empty() || line.front() == ';') return;
    GcodeError error = GcodeError::none;
    const GcodeLine g = parse_gcode_line(line, error);
    if (error != GcodeError::none) throw InputError(name, InputLocation::at_line(n), "malformed G-code word");
    if (g.is('M', 82)) relative_e = false;
    if (g.is('M', 83)) relative_e = true;
    if (g.is('G', 92) && (g.has('E') || g.present == 0)) e = g.get('E');  // a bare G92 zeroes every axis
    if (!(g.is('G', 0) || g.is('G', 1))) return;
    if (g.has('Z')) z = g.get('Z');
    if (!g.has('E')) return;
    const double de = relative_e ? g.get('E') : g.get('E') - e;
    if (!relative_e) e = g.get('E');
    if (de > 0 && (g.has('X') || g.has('Y')) && in_layer && !seen) {
      seen = true;
      add_top(out, z, n, name);
    }
  });
  return out;
}

PlanFile three_mf_profile(std::string_view bytes, const std::string& name) {
  const ZipReader zip(bytes, name);
  const auto profile = zip.read(prusa_profile_entry, 16u << 20);
  if (!profile)
    throw InputError(
        name, {},
        "a 3MF without PrusaSlicer's layer-height profile (" + std::string(prusa_profile_entry) + ")");
  PlanFile out{"3MF (PrusaSlicer layer-height profile)",
               prusa_profile_tops(*profile, name + ":" + std::string(prusa_profile_entry)),
               {}};
  out.lines.assign(out.tops.size(), 1);
  return out;
}

PlanFile plan_json_tops(std::string_view text, const std::string& name) {
  const PlanDocument doc = read_plan_json(text, name);
  PlanFile out{"salient plan JSON", {}, {}};
  for (const PlanLayer& l : doc.layers) add_top(out, l.z_top, 0, name);
  return out;
}

}  // namespace

std::vector<double> prusa_profile_tops(std::string_view profile, const std::string& name) {
  const auto bad = [&](const std::string& why) { return InputError(name, InputLocation::at_line(1), why); };
  profile = profile.substr(0, profile.find('\n'));
  const std::size_t bar = profile.find('|');
  if (!profile.starts_with("object_id=") || bar == std::string_view::npos)
    throw bad("not a layer-height profile (expected object_id=N|z;h;…)");
  std::vector<double> values;
  std::string_view rest = profile.substr(bar + 1);
  while (!rest.empty()) {
    const std::size_t semi = rest.find(';');
    const auto v = number_at(rest.substr(0, semi));
    if (!v) throw bad("malformed number in the profile");
    values.push_back(*v);
    if (semi == std::string_view::npos) break;
    rest.remove_prefix(semi + 1);
  }
  if (values.size() < 4 || values.size() % 2 != 0) throw bad("the profile needs pairs z;h, at least two");
  for (std::size_t i = 2; i < values.size(); i += 2)
    if (values[i] < values[i - 2])
      throw bad("the profile's z values go down at pair " + std::to_string(i / 2 + 1));
  // Piecewise linear in z between the points, constant beyond them (PrusaSlicer's reading).
  const auto height_at = [&](double z) {
    std::size_t i = 0;
    while (i + 2 < values.size() && values[i + 2] <= z) i += 2;
    if (i + 2 >= values.size() || values[i + 2] <= values[i]) return values[i + 1];
    const double t = (z - values[i]) / (values[i + 2] - values[i]);
    return values[i + 1] + std::clamp(t, 0.0, 1.0) * (values[i + 3] - values[i + 1]);
  };
  const double top = values[values.size() - 2];
  std::vector<double> tops;
  for (double z = 0; z < top - 1e-6;) {
    const double h = height_at(z + 1e-6);
    if (!(h >= 1e-3) || !std::isfinite(h))
      throw bad("layer height " + std::to_string(h) + " mm at z " + std::to_string(z) +
                " mm (must be at least 0.001 mm)");
    z = z + h > top - 1e-6 ? top : z + h;
    tops.push_back(z);
  }
  return tops;
}

PlanFile parse_plan_file(std::string_view bytes, const std::string& name) {
  std::size_t start = 0;
  while (start < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[start]))) ++start;
  if (start == bytes.size()) throw InputError(name, {}, "is empty: no layers to score");
  if (bytes.starts_with("PK\x03\x04")) return three_mf_profile(bytes, name);
  PlanFile out;
  if (bytes[start] == '{') {
    out = plan_json_tops(bytes, name);
  } else if (bytes.substr(0, 4096).find('\0') != std::string_view::npos) {
    throw InputError(name, {}, "unknown format: not a salient plan (JSON), G-code or 3MF");
  } else if (bytes.find("\n;Z:") != std::string_view::npos || bytes.starts_with(";Z:")) {
    out = gcode_z_comments(bytes, name);
  } else if (bytes.find(";LAYER:") != std::string_view::npos) {
    out = gcode_cura_layers(bytes, name);
  } else {
    throw InputError(name, {},
                     "unknown format: no ;Z: or ;LAYER: comments (G-code from PrusaSlicer, Cura or salient), "
                     "and not a salient plan (JSON) or 3MF");
  }
  if (out.tops.empty()) throw InputError(name, {}, "has no layers");
  return out;
}

PlanFile read_plan_file(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, {}, "cannot read");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_plan_file(bytes, name);
}

}  // namespace salient::core
