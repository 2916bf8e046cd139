// PrinterProfile: what the slicer and the G-code writer need to know about one printer, typed
// and validated once (loaded from TOML in config/printers/).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace salient::core {

enum class GcodeFlavor { marlin, reprap, sailfish };

std::optional<GcodeFlavor> parse_gcode_flavor(std::string_view name);
std::string_view gcode_flavor_name(GcodeFlavor flavor);

// A thumbnail size written into the G-code, pixels (PrusaSlicer's "thumbnails" setting).
struct ThumbnailSize {
  int width = 0, height = 0;
  bool operator==(const ThumbnailSize&) const = default;
};

struct PrinterProfile {
  std::string id;    // file stem, e.g. "replicator2x"
  std::string name;  // for people
  GcodeFlavor flavor = GcodeFlavor::marlin;
  // Build volume, mm. With origin_at_center the bed spans [-width/2, width/2] × [-depth/2, depth/2].
  double bed_width = 220, bed_depth = 220, max_height = 250;
  bool origin_at_center = false;
  double min_layer = 0.1, max_layer = 0.3;  // α and ᾱ, mm
  // The first layer's height, fixed (PrusaSlicer's first_layer_height: the plan optimises the layers
  // above it), and the height a user would print the whole model at otherwise (the baseline the
  // results compare against), mm.
  double first_layer_height = 0.2, default_layer_height = 0.2;
  double nozzle_diameter = 0.4, filament_diameter = 1.75;               // mm
  double extruder_temperature = 210, bed_temperature = 60;              // °C
  double retract_length = 0.8, retract_speed = 35;                      // mm, mm/s
  double print_speed = 50, first_layer_speed = 20, travel_speed = 150;  // mm/s
  double acceleration = 1000;                                           // mm/s²
  double jerk = 10;  // mm/s: the speed change allowed at a corner without slowing
  // Sections are simplified within this deviation (PrusaSlicer's gcode_resolution), mm; with
  // arc_fitting, runs of segments on a circle are written as G2/G3 (Marlin's ARC_SUPPORT).
  double gcode_resolution = 0.0125;
  bool arc_fitting = false;
  double solid_infill_below_area = 70;  // mm²: regions smaller than this are filled solid (PrusaSlicer's)
  int baud = 115200;                    // the USB serial link's rate, what a file's stream must fit
  std::string start_gcode, end_gcode;   // templates: {extruder_temperature}, {bed_temperature}, …
  // Thumbnails of the model written into the G-code's header ("gcode.thumbnails"): a printer
  // screen's icon and PrusaSlicer's default preview; empty: none.
  std::vector<ThumbnailSize> thumbnails{{16, 16}, {220, 124}};

  double bed_center_x() const { return origin_at_center ? 0 : bed_width / 2; }
  double bed_center_y() const { return origin_at_center ? 0 : bed_depth / 2; }
};

// Parses TOML text; `source` names it in errors. Throws InputError "SOURCE:LINE: …" for syntax
// errors, unknown keys (named in full, e.g. "bed.widht"), wrong types and impossible values.
PrinterProfile parse_printer_profile(std::string_view toml, const std::string& source);
PrinterProfile load_printer_profile(const std::filesystem::path& path);

// The profiles shipped in config/printers/, compiled in: ids, and one by id (nullopt if unknown).
std::vector<std::string> builtin_printer_ids();
std::optional<PrinterProfile> builtin_printer(std::string_view id);

}  // namespace salient::core
