// Printer profiles: the shipped ones load with the paper's numbers; mistakes are named.
#include "core/printer/printer_profile.hpp"

#include <doctest/doctest.h>

#include "core/common/input_error.hpp"

using namespace salient::core;

TEST_CASE("shipped profiles load, the Replicator 2X as in the paper") {
  const auto ids = builtin_printer_ids();
  CHECK(ids == std::vector<std::string>{"ender3", "generic-i3", "replicator2x"});
  for (const std::string& id : ids) CHECK(builtin_printer(id).has_value());
  const PrinterProfile r = *builtin_printer("replicator2x");
  CHECK(r.min_layer == 0.1);
  CHECK(r.max_layer == 0.4);
  CHECK(r.bed_width == 225);
  CHECK(r.bed_depth == 145);
  CHECK(r.max_height == 150);
  CHECK(r.flavor == GcodeFlavor::sailfish);
  CHECK(r.origin_at_center);
  CHECK(r.bed_center_x() == 0);
  CHECK(r.start_gcode.find("{extruder_temperature}") != std::string::npos);
  const PrinterProfile e = *builtin_printer("ender3");
  CHECK(e.flavor == GcodeFlavor::marlin);
  CHECK(e.bed_center_x() == 110);
  CHECK_FALSE(builtin_printer("prusa-xl").has_value());
}

TEST_CASE("profile mistakes are errors naming the key and line") {
  CHECK_THROWS_WITH_AS(parse_printer_profile("name = \"x\"\n[bed]\nwidht = 200\n", "p.toml"),
                       "p.toml:3: unknown key 'bed.widht'", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[bed]\nwidth = \"wide\"\n", "p.toml"),
                       "p.toml:2: 'bed.width' must be a number", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[layers]\nmin = -0.1\n", "p.toml"),
                       "p.toml:2: 'layers.min' must be a positive number", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[layers]\nmin = 0.3\nmax = 0.2\n", "p.toml"),
                       "p.toml: 'layers.min' (0.300000) is greater than 'layers.max'", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("flavor = \"klipper\"\n", "p.toml"),
                       "p.toml: 'flavor' must be marlin, reprap or sailfish, got 'klipper'", InputError);
  CHECK_THROWS_AS(parse_printer_profile("[bed\nwidth = 1\n", "p.toml"), InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("colour = 1\n", "p.toml"), "p.toml:1: unknown key 'colour'",
                       InputError);
}

TEST_CASE("the first layer, the baseline height, the G-code resolution, small solids and the baud rate") {
  const PrinterProfile g = *builtin_printer("generic-i3");
  CHECK(g.first_layer_height == 0.2);
  CHECK(g.default_layer_height == 0.2);
  CHECK(g.gcode_resolution == 0.0125);
  CHECK_FALSE(g.arc_fitting);
  CHECK(g.solid_infill_below_area == 70);
  CHECK(g.baud == 115200);
  const PrinterProfile p = parse_printer_profile(
      "[layers]\nfirst = 0.3\ndefault = 0.15\n[gcode]\nresolution = 0.05\narc_fitting = true\n"
      "[infill]\nsolid_below_area = 10\n[connection]\nbaud = 250000\n",
      "p.toml");
  CHECK(p.first_layer_height == 0.3);
  CHECK(p.default_layer_height == 0.15);
  CHECK(p.gcode_resolution == 0.05);
  CHECK(p.arc_fitting);
  CHECK(p.solid_infill_below_area == 10);
  CHECK(p.baud == 250000);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[layers]\nfirst = 0.5\n", "p.toml"),
                       "p.toml: 'layers.first' must lie between 'layers.min' and the nozzle "
                       "('extruder.nozzle_diameter')",
                       InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[layers]\ndefault = 0.35\n", "p.toml"),
                       "p.toml: 'layers.default' must lie between 'layers.min' and 'layers.max'", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[gcode]\nresolution = 0\n", "p.toml"),
                       "p.toml:2: 'gcode.resolution' must be between 0.0001 and 1", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[gcode]\narc_fitting = 1\n", "p.toml"),
                       "p.toml:2: 'gcode.arc_fitting' must be true or false", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[connection]\nbaud = 0\n", "p.toml"),
                       "p.toml:2: 'connection.baud' must be between 1200 and 4000000", InputError);
}

TEST_CASE("G-code thumbnail sizes: PrusaSlicer's defaults, a list of WxH, mistakes named") {
  CHECK(parse_printer_profile("", "p.toml").thumbnails == std::vector<ThumbnailSize>{{16, 16}, {220, 124}});
  CHECK(parse_printer_profile("[gcode]\nthumbnails = [\"32x32\", \"400x300\"]\n", "p.toml").thumbnails ==
        std::vector<ThumbnailSize>{{32, 32}, {400, 300}});
  CHECK(parse_printer_profile("[gcode]\nthumbnails = []\n", "p.toml").thumbnails.empty());
  for (const auto& id : builtin_printer_ids()) CHECK(!builtin_printer(id)->thumbnails.empty());
  CHECK_THROWS_WITH_AS(parse_printer_profile("[gcode]\nthumbnails = \"16x16\"\n", "p.toml"),
                       "p.toml:2: 'gcode.thumbnails' must be a list of sizes like [\"16x16\", \"220x124\"]",
                       InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[gcode]\nthumbnails = [16]\n", "p.toml"),
                       "p.toml:2: 'gcode.thumbnails' must be a list of strings like \"220x124\"", InputError);
  CHECK_THROWS_WITH_AS(parse_printer_profile("[gcode]\nthumbnails = [\"16x16\", \"220*124\"]\n", "p.toml"),
                       "p.toml:2: 'gcode.thumbnails' entry '220*124' must be WIDTHxHEIGHT, e.g. \"220x124\"",
                       InputError);
  CHECK_THROWS_WITH_AS(
      parse_printer_profile("[gcode]\nthumbnails = [\"0x16\"]\n", "p.toml"),
      "p.toml:2: 'gcode.thumbnails' entry '0x16': width and height must be between 1 and 2048", InputError);
  CHECK_THROWS_AS(parse_printer_profile("[gcode]\nthumbnails = [\"16x16x2\"]\n", "p.toml"), InputError);
  CHECK_THROWS_WITH_AS(
      parse_printer_profile(
          "[gcode]\nthumbnails = [\"1x1\",\"1x1\",\"1x1\",\"1x1\",\"1x1\",\"1x1\",\"1x1\",\"1x1\",\"1x1\"]\n",
          "p.toml"),
      "p.toml:2: 'gcode.thumbnails' has 9 sizes, at most 8 are allowed", InputError);
}
