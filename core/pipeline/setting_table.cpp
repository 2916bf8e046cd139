// The settings table's rows, and what is derived from them without a front end.
#include "core/pipeline/setting_table.hpp"

#include <algorithm>
#include <locale>
#include <sstream>
#include <type_traits>

#include "core/common/input_error.hpp"
#include "core/mesh/placement.hpp"

namespace salient::core {
namespace {

using Value = std::optional<SettingValue>;

double number(const SettingValue& v) {
  return std::get<double>(v);
}
std::int64_t integer(const SettingValue& v) {
  return std::get<std::int64_t>(v);
}
bool flag(const SettingValue& v) {
  return std::get<bool>(v);
}
const std::string& text(const SettingValue& v) {
  return std::get<std::string>(v);
}

template <class T>
Value optional_value(const std::optional<T>& v) {
  if (!v) return std::nullopt;
  if constexpr (std::is_integral_v<T>)
    return SettingValue(std::int64_t(*v));
  else
    return SettingValue(*v);
}

std::string names_text(const std::vector<std::string_view>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out.append(i == 0 ? "" : i + 1 == names.size() ? " or " : ", ").append(names[i]);
  return out;
}

// The printer and the planner (first: what a job is sliced for and with).
void add_printer_and_planner(std::vector<Setting>& t) {
  using I = SettingId;
  t.push_back({.id = I::printer,
               .key = "printer",
               .flag = "--printer",
               .type = SettingType::text,
               .help = "Printer profile: built-in id (ender3, generic-i3, replicator2x) or a .toml file",
               .member = "printer",
               .commands = for_slice,
               .get = [](const Settings& s) -> Value { return s.printer; },
               .set = [](Settings& s, const SettingValue& v) { s.printer = text(v); }});
  t.push_back(
      {.id = I::planner,
       .key = "planner",
       .flag = "--planner",
       .type = SettingType::choice,
       .help = "Planner: exact, adapslice, hms, uniform, cusp, stepwise, ha13, ceo, random, fine, coarse",
       .member = "slice.plan.planner",
       .commands = for_plan | for_slice,
       .get = [](const Settings& s) -> Value { return std::string(to_string(s.slice.plan.planner)); },
       .set =
           [](Settings& s, const SettingValue& v) {
             const auto kind = parse_planner(text(v));
             if (!kind) throw InputError(SettingId::planner, "unknown planner '" + text(v) + "'");
             s.slice.plan.planner = *kind;
           },
       .choices = planner_names});
}

// How the model stands and how big it is.
void add_placement_rows(std::vector<Setting>& t) {
  using I = SettingId;
  t.push_back(
      {.id = I::up,
       .key = "up",
       .flag = "--up",
       .type = SettingType::text,
       .help = "Up: x, y, z, a direction DX,DY,DZ, or auto (the best of three orientations, paper §6; "
               "with --height, the tallest of them gets that height)",
       .member = "slice.plan.mesh.up",
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return s.slice.plan.mesh.up; },
       .set =
           [](Settings& s, const SettingValue& v) {
             if (!parse_up_axis(text(v)) && !parse_up_direction(text(v)) && text(v) != "auto")
               throw InputError(SettingId::up,
                                "expected x, y, z, auto or a direction like 0,-1,0.2, got '" + text(v) + "'");
             s.slice.plan.mesh.up = text(v);
           }});
  t.push_back({.id = I::height,
               .key = "height",
               .flag = "--height",
               .type = SettingType::number,
               .unit = "mm",
               .min = 0.1,
               .max = 10000,
               .help = "Scale the model to this height",
               .member = "slice.plan.mesh.height",
               .canonical = InCanonical::when_given,
               .get = [](const Settings& s) -> Value { return optional_value(s.slice.plan.mesh.height); },
               .set = [](Settings& s, const SettingValue& v) { s.slice.plan.mesh.height = number(v); }});
  t.push_back({.id = I::scale,
               .key = "scale",
               .flag = "--scale",
               .type = SettingType::number,
               .min = 1e-6,
               .max = 1e6,
               .help = "Scale the model by this factor",
               .member = "slice.plan.mesh.scale",
               .get = [](const Settings& s) -> Value { return s.slice.plan.mesh.scale; },
               .set = [](Settings& s, const SettingValue& v) { s.slice.plan.mesh.scale = number(v); }});
}

// The layers: limits, grid and the target (ρ, or a count).
void add_layer_rows(std::vector<Setting>& t) {
  using I = SettingId;
  t.push_back({.id = I::min_layer,
               .key = "min_layer",
               .flag = "--min-layer",
               .type = SettingType::number,
               .unit = "mm",
               .min = 0.01,
               .max = 10,
               .help = "Thinnest printable layer α",
               .member = "slice.plan.min_layer (and slice.min_layer_from_printer = false)",
               .canonical = InCanonical::when_given,
               .from_printer = true,
               .get = [](const Settings& s) -> Value {
                 if (s.slice.min_layer_from_printer) return std::nullopt;
                 return s.slice.plan.min_layer;
               },
               .set =
                   [](Settings& s, const SettingValue& v) {
                     s.slice.plan.min_layer = number(v), s.slice.min_layer_from_printer = false;
                   }});
  t.push_back({.id = I::max_layer,
               .key = "max_layer",
               .flag = "--max-layer",
               .type = SettingType::number,
               .unit = "mm",
               .min = 0.01,
               .max = 10,
               .help = "Thickest printable layer ᾱ",
               .member = "slice.plan.max_layer (and slice.max_layer_from_printer = false)",
               .canonical = InCanonical::when_given,
               .from_printer = true,
               .get = [](const Settings& s) -> Value {
                 if (s.slice.max_layer_from_printer) return std::nullopt;
                 return s.slice.plan.max_layer;
               },
               .set =
                   [](Settings& s, const SettingValue& v) {
                     s.slice.plan.max_layer = number(v), s.slice.max_layer_from_printer = false;
                   }});
  t.push_back({.id = I::grid,
               .key = "grid",
               .flag = "--grid",
               .type = SettingType::number,
               .unit = "mm",
               .min = 0.001,
               .max = 1,
               .help = "Grid δ that layer boundaries snap to",
               .member = "slice.plan.grid",
               .get = [](const Settings& s) -> Value { return s.slice.plan.grid; },
               .set = [](Settings& s, const SettingValue& v) { s.slice.plan.grid = number(v); }});
  t.push_back({.id = I::rho,
               .key = "rho",
               .flag = "--rho",
               .type = SettingType::number,
               .min = 0,
               .max = 1,
               .help = "Allowed loss ε = ρ·E(coarse), 0..1 (default 0.05)",
               .member = "slice.plan.rho",
               .canonical = InCanonical::when_given,
               .excludes = {I::layers, I::layer_height},
               .get = [](const Settings& s) -> Value { return optional_value(s.slice.plan.rho); },
               .set = [](Settings& s, const SettingValue& v) { s.slice.plan.rho = number(v); }});
  t.push_back({.id = I::layers,
               .key = "layers",
               .flag = "--layers",
               .type = SettingType::integer,
               .min = 1,
               .max = 100000,
               .help = "Plan exactly this many layers",
               .member = "slice.plan.layers",
               .canonical = InCanonical::when_given,
               .excludes = {I::rho, I::layer_height},
               .get = [](const Settings& s) -> Value { return optional_value(s.slice.plan.layers); },
               .set = [](Settings& s,
                         const SettingValue& v) { s.slice.plan.layers = static_cast<int>(integer(v)); }});
  t.push_back({.id = I::layer_height,
               .key = "layer_height",
               .flag = "--layer-height",
               .type = SettingType::number,
               .unit = "mm",
               .min = 0.01,
               .max = 10,
               .help = "Uniform thickness, for --planner uniform",
               .member = "slice.plan.layer_height",
               .canonical = InCanonical::when_given,
               .excludes = {I::rho, I::layers},
               .get = [](const Settings& s) -> Value { return optional_value(s.slice.plan.layer_height); },
               .set = [](Settings& s, const SettingValue& v) { s.slice.plan.layer_height = number(v); }});
}

// How quality is measured.
void add_quality_rows(std::vector<Setting>& t) {
  using I = SettingId;
  t.push_back({.id = I::metric,
               .key = "metric",
               .flag = "--metric",
               .type = SettingType::choice,
               .help = "Quality metric: area (ours) or paper (eq. 1)",
               .member = "slice.plan.metric",
               .cli_checks = true,
               .get = [](const Settings& s) -> Value { return std::string(to_string(s.slice.plan.metric)); },
               .set =
                   [](Settings& s, const SettingValue& v) {
                     const auto m = parse_metric(text(v));
                     if (!m)
                       throw InputError(SettingId::metric,
                                        "expected " + names_text(metric_names()) + ", got '" + text(v) + "'");
                     s.slice.plan.metric = *m;
                   },
               .choices = metric_names});
  t.push_back(
      {.id = I::objective,
       .key = "objective",
       .flag = "--objective",
       .type = SettingType::choice,
       .help =
           "What exact minimises within ε: time (the estimated printing time) or layers (the paper's T = N)",
       .member = "slice.plan.objective",
       .canonical = InCanonical::when_changed,
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return std::string(to_string(s.slice.plan.objective)); },
       .set =
           [](Settings& s, const SettingValue& v) {
             const auto g = parse_plan_goal(text(v));
             if (!g)
               throw InputError(SettingId::objective,
                                "expected " + names_text(plan_goal_names()) + ", got '" + text(v) + "'");
             s.slice.plan.objective = *g;
           },
       .choices = plan_goal_names});
  t.push_back(
      {.id = I::saliency,
       .key = "saliency",
       .flag = "--saliency",
       .type = SettingType::choice,
       .help = "Saliency: spectral (the paper's), lee05, painted (vertex quality/colour) or uniform",
       .member = "slice.plan.saliency",
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return std::string(to_string(s.slice.plan.saliency)); },
       .set =
           [](Settings& s, const SettingValue& v) {
             const auto m = parse_saliency_method(text(v));
             if (!m)
               throw InputError(SettingId::saliency, "expected " + names_text(saliency_method_names()) +
                                                         ", got '" + text(v) + "'");
             s.slice.plan.saliency = *m;
           },
       .choices = saliency_method_names});
  t.push_back(
      {.id = I::saliency_file,
       .key = "saliency_file",
       .flag = "--saliency-file",
       .type = SettingType::text,
       .help = "Per-vertex saliency, one value per line in the model file's vertex order (implies painted)",
       .member = "slice.plan.saliency_file",
       .canonical = InCanonical::when_given,
       .not_a_job_setting = "a path on the client's machine; a job sends painted saliency as the model "
                            "file's vertex quality or colour (\"saliency\": \"painted\")",
       .get = [](const Settings& s) -> Value {
         if (s.slice.plan.saliency_file.empty()) return std::nullopt;
         return s.slice.plan.saliency_file;
       },
       .set = [](Settings& s, const SettingValue& v) { s.slice.plan.saliency_file = text(v); }});
  t.push_back(
      {.id = I::seed,
       .key = "seed",
       .flag = "--seed",
       .type = SettingType::integer,
       .min = 0,
       .max = 1e15,
       .help = "Seed for the random planner",
       .member = "slice.plan.seed",
       .get = [](const Settings& s) -> Value { return std::int64_t(s.slice.plan.seed); },
       .set = [](Settings& s, const SettingValue& v) { s.slice.plan.seed = std::uint64_t(integer(v)); }});
}

// SegOpt (paper §5).
void add_segment_rows(std::vector<Setting>& t) {
  using I = SettingId;
  t.push_back(
      {.id = I::segment,
       .key = "segment",
       .flag = "--segment",
       .type = SettingType::flag,
       .help =
           "SegOpt (paper §5): cut the model by a vertical plane where slicing its parts apart saves time",
       .member = "slice.plan.segment",
       .canonical = InCanonical::when_changed,
       .get = [](const Settings& s) -> Value { return s.slice.plan.segment; },
       .set = [](Settings& s, const SettingValue& v) { s.slice.plan.segment = flag(v); }});
  t.push_back(
      {.id = I::segment_depth,
       .key = "segment_depth",
       .flag = "--segment-depth",
       .type = SettingType::integer,
       .min = 1,
       .max = 4,
       .help = "With --segment: levels of cutting (2 and more cut each part again)",
       .member = "slice.plan.segment_depth",
       .canonical = InCanonical::when_changed,
       .only_with = I::segment,
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return std::int64_t(s.slice.plan.segment_depth); },
       .set = [](Settings& s,
                 const SettingValue& v) { s.slice.plan.segment_depth = static_cast<int>(integer(v)); }});
  t.push_back(
      {.id = I::segment_planes,
       .key = "segment_planes",
       .flag = "--segment-planes",
       .type = SettingType::integer,
       .min = 1,
       .max = 20,
       .help =
           "With --segment: how many of the best planes (by seam cost) to plan and time; the fastest is kept",
       .member = "slice.plan.segment_planes",
       .canonical = InCanonical::when_changed,
       .only_with = I::segment,
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return std::int64_t(s.slice.plan.segment_planes); },
       .set = [](Settings& s,
                 const SettingValue& v) { s.slice.plan.segment_planes = static_cast<int>(integer(v)); }});
}

// Toolpaths and support (slice only).
void add_toolpath_rows(std::vector<Setting>& t) {
  using I = SettingId;
  t.push_back({.id = I::walls,
               .key = "walls",
               .flag = "--walls",
               .type = SettingType::integer,
               .min = 1,
               .max = 20,
               .help = "Number of walls",
               .member = "slice.toolpaths.walls",
               .commands = for_slice,
               .cli_checks = true,
               .get = [](const Settings& s) -> Value { return std::int64_t(s.slice.toolpaths.walls); },
               .set = [](Settings& s,
                         const SettingValue& v) { s.slice.toolpaths.walls = static_cast<int>(integer(v)); }});
  t.push_back(
      {.id = I::infill,
       .key = "infill",
       .flag = "--infill",
       .type = SettingType::number,
       .min = 0,
       .max = 1,
       .help = "Sparse infill density, 0..1",
       .member = "slice.toolpaths.infill_density",
       .commands = for_slice,
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return s.slice.toolpaths.infill_density; },
       .set = [](Settings& s, const SettingValue& v) { s.slice.toolpaths.infill_density = number(v); }});
  t.push_back({.id = I::line_width,
               .key = "line_width",
               .flag = "--line-width",
               .type = SettingType::number,
               .unit = "mm",
               .min = 0.05,
               .max = 5,
               .help = "Extrusion width",
               .member = "slice.toolpaths.line_width",
               .commands = for_slice,
               .canonical = InCanonical::when_changed,
               .get = [](const Settings& s) -> Value { return s.slice.toolpaths.line_width; },
               .set = [](Settings& s, const SettingValue& v) { s.slice.toolpaths.line_width = number(v); }});
  t.push_back(
      {.id = I::top_thickness,
       .key = "top_thickness",
       .flag = "--top-thickness",
       .type = SettingType::number,
       .unit = "mm",
       .min = 0,
       .max = 10,
       .help = "Solid skin under top surfaces",
       .member = "slice.toolpaths.top_thickness",
       .commands = for_slice,
       .canonical = InCanonical::when_changed,
       .get = [](const Settings& s) -> Value { return s.slice.toolpaths.top_thickness; },
       .set = [](Settings& s, const SettingValue& v) { s.slice.toolpaths.top_thickness = number(v); }});
  t.push_back(
      {.id = I::bottom_thickness,
       .key = "bottom_thickness",
       .flag = "--bottom-thickness",
       .type = SettingType::number,
       .unit = "mm",
       .min = 0,
       .max = 10,
       .help = "Solid skin over bottom surfaces",
       .member = "slice.toolpaths.bottom_thickness",
       .commands = for_slice,
       .canonical = InCanonical::when_changed,
       .get = [](const Settings& s) -> Value { return s.slice.toolpaths.bottom_thickness; },
       .set = [](Settings& s, const SettingValue& v) { s.slice.toolpaths.bottom_thickness = number(v); }});
  t.push_back({.id = I::combine_infill,
               .key = "combine_infill",
               .flag = "--combine-infill",
               .type = SettingType::flag,
               .help = "Print sparse infill once for thin layers that fit under the printer's thickest layer",
               .member = "slice.combine_infill",
               .commands = for_slice,
               .canonical = InCanonical::when_changed,
               .get = [](const Settings& s) -> Value { return s.slice.combine_infill; },
               .set = [](Settings& s, const SettingValue& v) { s.slice.combine_infill = flag(v); }});
  t.push_back({.id = I::support,
               .key = "support",
               .flag = "--support",
               .type = SettingType::flag,
               .help = "Add support under overhangs",
               .member = "slice.support",
               .commands = for_slice,
               .get = [](const Settings& s) -> Value { return s.slice.support; },
               .set = [](Settings& s, const SettingValue& v) { s.slice.support = flag(v); }});
  t.push_back(
      {.id = I::support_angle,
       .key = "support_angle",
       .flag = "--support-angle",
       .type = SettingType::number,
       .unit = "°",
       .min = 0,
       .max = 89,
       .help = "Overhangs steeper than this from vertical get support",
       .member = "slice.support_settings.angle",
       .commands = for_slice,
       .cli_checks = true,
       .get = [](const Settings& s) -> Value { return s.slice.support_settings.angle; },
       .set = [](Settings& s, const SettingValue& v) { s.slice.support_settings.angle = number(v); }});
}

std::vector<Setting> make_table() {
  std::vector<Setting> t;
  add_printer_and_planner(t);
  add_placement_rows(t);
  add_layer_rows(t);
  add_quality_rows(t);
  add_segment_rows(t);
  add_toolpath_rows(t);
  return t;
}

}  // namespace
}  // namespace salient::core

namespace salient::core {

const std::vector<Setting>& setting_table() {
  static const std::vector<Setting> table = make_table();
  return table;
}

const Setting& setting(SettingId id) {
  return setting_table().at(static_cast<std::size_t>(id));
}

const Setting* setting_by_key(std::string_view key) {
  for (const Setting& s : setting_table())
    if (s.key == key) return &s;
  return nullptr;
}

std::string value_text(const SettingValue& value) {
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const std::string* t = std::get_if<std::string>(&value)) return *t;
  std::ostringstream out;  // as CLI11 prints a default: "0.4", "1e-06"
  out.imbue(std::locale::classic());
  if (const double* d = std::get_if<double>(&value))
    out << *d;
  else
    out << std::get<std::int64_t>(value);
  return out.str();
}

std::string default_text(const Setting& setting) {
  Settings defaults;  // with the layer limits of `plan`, which has no printer
  defaults.slice.min_layer_from_printer = defaults.slice.max_layer_from_printer = false;
  const Value v = setting.get(defaults);
  return v ? value_text(*v) : std::string();
}

std::vector<std::pair<const Setting*, SettingValue>> canonical_values(const Settings& settings) {
  static const Settings defaults;
  std::vector<std::pair<const Setting*, SettingValue>> out;
  for (const Setting& s : setting_table()) {
    if (!s.not_a_job_setting.empty()) continue;
    Value v = s.get(settings);
    if (!v) continue;
    if (s.canonical == InCanonical::when_changed && *v == s.get(defaults)) continue;
    if (s.only_with) {
      const Value on = setting(*s.only_with).get(settings);
      if (!on || !std::get<bool>(*on)) continue;
    }
    out.emplace_back(&s, std::move(*v));
  }
  return out;
}

std::string settings_markdown() {
  std::string out =
      "| job key | CLI option | type | range | default | meaning |\n"
      "|---|---|---|---|---|---|\n";
  static const char* const types[] = {"number", "integer", "true/false", "text", "choice"};
  for (const Setting& s : setting_table()) {
    std::string range;
    if (s.type == SettingType::number || s.type == SettingType::integer)
      range =
          value_text(s.min) + " to " + value_text(s.max) + (s.unit.empty() ? "" : " " + std::string(s.unit));
    if (s.choices) range = names_text(s.choices());
    std::string def = s.from_printer ? "the printer's" : default_text(s);
    if (def.empty()) def = "unset";
    const bool job = s.not_a_job_setting.empty();
    const std::string key = job ? "`" + std::string(s.key) + "`" : "— (CLI only)";
    std::string what(s.help);
    if (!job) what += "; not a job setting: " + std::string(s.not_a_job_setting);
    out += "| " + key + " | `" + std::string(s.flag) + "` | " + types[static_cast<int>(s.type)] + " | " +
           range + " | " + def + " | " + what + " |\n";
  }
  return out;
}

}  // namespace salient::core
