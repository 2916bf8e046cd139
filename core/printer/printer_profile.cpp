// PrinterProfile loading with toml++ (the one file that includes it). Every key is looked up
// through a table of known keys; anything left over is an error that names it and its line.
#include "core/printer/printer_profile.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <utility>

#include "core/common/input_error.hpp"
#include "core/common/name_table.hpp"
#include "core/common/toml_table_reader.hpp"
#include "core/printer/builtin_profiles.hpp"

namespace salient::core {

namespace {
// The one name table of the G-code flavours.
constexpr NameTable<GcodeFlavor, 3> kFlavorNames{
    {{GcodeFlavor::marlin, "marlin"}, {GcodeFlavor::reprap, "reprap"}, {GcodeFlavor::sailfish, "sailfish"}}};

// PrusaSlicer's limits for one thumbnail side, and a bound on how many (each is in every file).
constexpr int kMaxThumbnailSide = 2048;
constexpr std::size_t kMaxThumbnails = 8;

// "gcode.thumbnails": an array of "WIDTHxHEIGHT" strings, e.g. ["16x16", "220x124"].
std::vector<ThumbnailSize> read_thumbnail_sizes(TableReader& r) {
  std::vector<ThumbnailSize> sizes;
  const toml::array* list = r.array("thumbnails", "a list of sizes like [\"16x16\", \"220x124\"]");
  if (!list) return {{16, 16}, {220, 124}};
  if (list->size() > kMaxThumbnails)
    r.fail(*list, "thumbnails",
           "has " + std::to_string(list->size()) + " sizes, at most " + std::to_string(kMaxThumbnails) +
               " are allowed");
  for (const toml::node& item : *list) {
    const auto text = item.value<std::string>();
    if (!text) r.fail(item, "thumbnails", "must be a list of strings like \"220x124\"");
    ThumbnailSize size;
    char x = 0, tail = 0;
    if (std::sscanf(text->c_str(), "%d%c%d%c", &size.width, &x, &size.height, &tail) != 3 || x != 'x')
      r.fail(item, "thumbnails", "entry '" + *text + "' must be WIDTHxHEIGHT, e.g. \"220x124\"");
    if (size.width < 1 || size.height < 1 || size.width > kMaxThumbnailSide ||
        size.height > kMaxThumbnailSide)
      r.fail(item, "thumbnails",
             "entry '" + *text + "': width and height must be between 1 and " +
                 std::to_string(kMaxThumbnailSide));
    sizes.push_back(size);
  }
  return sizes;
}

}  // namespace

std::optional<GcodeFlavor> parse_gcode_flavor(std::string_view name) {
  return value_in(kFlavorNames, name);
}

std::string_view gcode_flavor_name(GcodeFlavor flavor) {
  return name_in(kFlavorNames, flavor, "marlin");
}

PrinterProfile parse_printer_profile(std::string_view text, const std::string& source) {
  const toml::table root = parse_toml(text, source);
  PrinterProfile p;
  p.id = std::filesystem::path(source).stem().string();
  TableReader top(root, "", source);
  top.text("name", p.name);
  std::string flavor = "marlin";
  top.text("flavor", flavor);
  const auto parsed_flavor = parse_gcode_flavor(flavor);
  if (!parsed_flavor)
    throw InputError(source, {}, "'flavor' must be marlin, reprap or sailfish, got '" + flavor + "'");
  p.flavor = *parsed_flavor;
  std::string origin = "corner";
  read_section(top, "bed", source, [&](TableReader& r) {
    r.number("width", p.bed_width);
    r.number("depth", p.bed_depth);
    r.number("height", p.max_height);
    r.text("origin", origin);
  });
  if (origin != "corner" && origin != "center")
    throw InputError(source, {}, "'bed.origin' must be corner or center, got '" + origin + "'");
  p.origin_at_center = origin == "center";
  read_section(top, "layers", source, [&](TableReader& r) {
    r.number("min", p.min_layer);
    r.number("max", p.max_layer);
    r.number("first", p.first_layer_height);
    r.number("default", p.default_layer_height);
  });
  read_section(top, "extruder", source, [&](TableReader& r) {
    r.number("nozzle_diameter", p.nozzle_diameter);
    r.number("filament_diameter", p.filament_diameter);
    r.number("temperature", p.extruder_temperature, false);
    r.number("retract_length", p.retract_length, false);
    r.number("retract_speed", p.retract_speed);
  });
  read_section(top, "bed_heater", source,
               [&](TableReader& r) { r.number("temperature", p.bed_temperature, false); });
  read_section(top, "motion", source, [&](TableReader& r) {
    r.number("print_speed", p.print_speed);
    r.number("first_layer_speed", p.first_layer_speed);
    r.number("travel_speed", p.travel_speed);
    r.number("acceleration", p.acceleration);
    r.number("jerk", p.jerk);
  });
  read_section(top, "gcode", source, [&](TableReader& r) {
    r.text("start", p.start_gcode);
    r.text("end", p.end_gcode);
    r.number("resolution", p.gcode_resolution, 0.0001, 1.0);
    r.boolean("arc_fitting", p.arc_fitting);
    p.thumbnails = read_thumbnail_sizes(r);
  });
  read_section(top, "infill", source,
               [&](TableReader& r) { r.number("solid_below_area", p.solid_infill_below_area, 0.0, 1e6); });
  read_section(top, "connection", source, [&](TableReader& r) { r.integer("baud", p.baud, 1200, 4000000); });
  top.reject_unknown();
  if (p.min_layer > p.max_layer)
    throw InputError(source, {},
                     "'layers.min' (" + std::to_string(p.min_layer) + ") is greater than 'layers.max'");
  if (p.max_layer > p.nozzle_diameter)
    throw InputError(source, {}, "'layers.max' is thicker than the nozzle ('extruder.nozzle_diameter')");
  if (p.first_layer_height < p.min_layer || p.first_layer_height > p.nozzle_diameter)
    throw InputError(
        source, {},
        "'layers.first' must lie between 'layers.min' and the nozzle ('extruder.nozzle_diameter')");
  if (p.default_layer_height < p.min_layer || p.default_layer_height > p.max_layer)
    throw InputError(source, {}, "'layers.default' must lie between 'layers.min' and 'layers.max'");
  if (p.name.empty()) p.name = p.id;
  return p;
}

PrinterProfile load_printer_profile(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, {}, "cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_printer_profile(text.str(), name);
}

std::vector<std::string> builtin_printer_ids() {
  std::vector<std::string> ids;
  for (const auto& [id, text] : builtin_profile_texts()) ids.emplace_back(id);
  return ids;
}

std::optional<PrinterProfile> builtin_printer(std::string_view id) {
  for (const auto& [name, text] : builtin_profile_texts())
    if (name == id) return parse_printer_profile(text, std::string(name) + ".toml");
  return std::nullopt;
}

}  // namespace salient::core
