// The G-code behind OctoPrint's printer controls, and what of a settings write is kept: exact
// commands for good values, 400 for bad ones (out of range, not numbers, unknown tools and axes,
// moves beyond the printer's volume), unknown settings dropped.
#include "server/api/octoprint_printer_commands.hpp"

#include <doctest/doctest.h>

#include "server/api/octoprint_settings.hpp"
#include "server/http/router.hpp"

using namespace salient::server;
using nlohmann::json;
using Lines = std::vector<std::string>;

namespace {
template <typename F>
int status_of_call(F f) {
  try {
    f();
    return 200;
  } catch (const ApiError& e) {
    return e.status();
  }
}
}  // namespace

TEST_CASE("temperatures: targets with offsets, bounds and types") {
  CHECK(tool_target_gcode(json{{"tool0", 210}}, 0) == Lines{"M104 S210"});
  CHECK(tool_target_gcode(json{{"tool0", 200}}, -7.5) == Lines{"M104 S192.5"});
  CHECK(tool_target_gcode(json{{"tool0", 0}}, 10) == Lines{"M104 S0"});  // off stays off
  CHECK(bed_target_gcode(json(60), 0) == Lines{"M140 S60"});
  for (const json& bad : {json{{"tool0", -1}}, json{{"tool0", 321}}, json{{"tool0", "200"}},
                          json{{"tool1", 200}}, json::array(), json::object()})
    CHECK_MESSAGE(status_of_call([&] { tool_target_gcode(bad, 0); }) == 400, bad.dump());
  CHECK(status_of_call([] { bed_target_gcode(json(151), 0); }) == 400);
  CHECK(status_of_call([] { checked_offset(json(50.5), "bed"); }) == 400);
  CHECK(checked_offset(json(-50), "bed") == -50);
  CHECK(tool_select_gcode(json("tool0")) == Lines{"T0"});
  CHECK(status_of_call([] { tool_select_gcode(json("tool9")); }) == 400);
}

TEST_CASE("jog: relative within the bed's size, absolute within its volume, origin as the profile says") {
  salient::core::PrinterProfile p;  // 220 × 220 × 250, origin at a corner
  CHECK(jog_gcode(json{{"x", 10}, {"z", -0.5}}, p) == Lines{"G91", "G1 X10 Z-0.5 F6000", "G90"});
  CHECK(jog_gcode(json{{"z", 2}}, p) == Lines{"G91", "G1 Z2 F200", "G90"});
  // FDM Monster's jog: every axis, 0 for those that stay.
  CHECK(jog_gcode(json{{"x", 0}, {"y", 0}, {"z", 5}}, p) == Lines{"G91", "G1 Z5 F200", "G90"});
  CHECK(jog_gcode(json{{"x", 0}, {"y", 0}, {"z", 0}}, p).empty());
  CHECK(jog_gcode(json{{"x", 0}, {"absolute", true}}, p) == Lines{"G90", "G1 X0 F6000"});
  CHECK(jog_gcode(json{{"x", 220}, {"y", 0}, {"absolute", true}, {"speed", 1500}}, p) ==
        Lines{"G90", "G1 X220 Y0 F1500"});
  for (const json& bad : {json{{"x", 1e9}}, json{{"x", -221}}, json{{"x", -1}, {"absolute", true}},
                          json{{"z", 251}, {"absolute", true}}, json{{"x", "1"}}, json::object(),
                          json{{"x", 1}, {"speed", 0}}, json{{"x", 1}, {"speed", 1e9}}})
    CHECK_MESSAGE(status_of_call([&] { jog_gcode(bad, p); }) == 400, bad.dump());
  p.origin_at_center = true;
  CHECK(jog_gcode(json{{"x", -110}, {"absolute", true}}, p) == Lines{"G90", "G1 X-110 F6000"});
  CHECK(status_of_call([&] { jog_gcode(json{{"x", 111}, {"absolute", true}}, p); }) == 400);
}

TEST_CASE("home, extrude, feed and flow rates") {
  CHECK(home_gcode(json{{"axes", {"x", "y", "x"}}}) == Lines{"G28 X0 Y0"});
  for (const json& bad :
       {json::object(), json{{"axes", "xyz"}}, json{{"axes", json::array()}}, json{{"axes", {"e"}}}})
    CHECK_MESSAGE(status_of_call([&] { home_gcode(bad); }) == 400, bad.dump());
  CHECK(extrude_gcode(json{{"amount", -2.5}}) == Lines{"G91", "M83", "G1 E-2.5 F300", "M82", "G90"});
  CHECK(status_of_call([] { extrude_gcode(json{{"amount", 1001}}); }) == 400);
  CHECK(status_of_call([] { extrude_gcode(json{{"amount", nullptr}}); }) == 400);
  CHECK(feedrate_gcode(json(150)) == "M220 S150");
  CHECK(feedrate_gcode(json(0.5)) == "M220 S50");
  CHECK(flowrate_gcode(json(1.1)) == "M221 S110");
  CHECK(status_of_call([] { flowrate_gcode(json(130)); }) == 400);
  CHECK(status_of_call([] { feedrate_gcode(json(2.5)); }) == 400);
}

TEST_CASE("settings writes: known writable keys of the right type kept, the rest dropped quietly") {
  const json defaults = {{"appearance", {{"name", "salient"}, {"color", "default"}}},
                         {"feature", {{"sdSupport", false}}},
                         {"webcam", {{"streamUrl", ""}, {"flipH", false}}},
                         {"temperature", {{"profiles", json::array()}}},
                         {"gcodeAnalysis", {{"runAt", "idle"}}},
                         {"plugins", json::object()}};
  const json body = {{"appearance", {{"name", "Farm 1"}, {"color", 5}, {"unknown", 1}}},
                     {"feature", {{"sdSupport", true}}},
                     {"webcam", {{"streamUrl", std::string(300, 'u')}, {"flipH", true}}},
                     {"temperature", {{"profiles", {{{"name", "PETG"}, {"extruder", 235}}}}}},
                     {"gcodeAnalysis", {{"runAt", "never"}}},
                     {"plugins", {{"firmwareupdater", {{"flash", true}}}}},
                     {"bogus", {{"x", 1}}}};
  const json kept = accepted_settings(defaults, body);
  CHECK(kept == json{{"appearance", {{"name", "Farm 1"}}},
                     {"webcam", {{"flipH", true}}},
                     {"temperature", {{"profiles", {{{"name", "PETG"}, {"extruder", 235}}}}}},
                     {"gcodeAnalysis", {{"runAt", "never"}}}});
  CHECK(accepted_settings(defaults, json{{"appearance", "x"}}).empty());
}
