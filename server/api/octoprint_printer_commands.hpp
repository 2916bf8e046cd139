// The G-code behind OctoPrint's printer controls (/api/printer/tool, bed, printhead), checked
// before anything is sent: ApiError 400 with a clear message for a value that is not a number,
// out of range, an unknown tool or axis, or a move that would leave the printer's volume. Pure:
// the routes send the result through Printer::command. Included from .cpp files only.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/printer/printer_profile.hpp"

namespace salient::server {

// Highest targets accepted (°C): above every common firmware's MAXTEMP for a PTFE/all-metal
// hotend and a bed, so that a typo (2100 for 210) is refused rather than sent.
constexpr double kMaxToolTemperature = 320, kMaxBedTemperature = 150;
constexpr double kMaxOffset = 50;       // OctoPrint's bound on temperature offsets (°C)
constexpr double kMaxExtrudeMm = 1000;  // one extrude request, either way
constexpr double kMaxFeedMmPerMin = 60000;

// {"targets": {"tool0": T}} → M104 S…; `offset` is added to a target that is not 0 (off).
std::vector<std::string> tool_target_gcode(const nlohmann::json& targets, double offset);
// {"target": T} → M140 S…
std::vector<std::string> bed_target_gcode(const nlohmann::json& target, double offset);
// A temperature offset ([-50, 50] °C), for "tool0" or "bed".
double checked_offset(const nlohmann::json& value, const std::string& what);
// {"tool": "tool0"} → T0 (this printer has one tool).
std::vector<std::string> tool_select_gcode(const nlohmann::json& tool);
// {"amount": mm, "speed": mm/min} → relative E move.
std::vector<std::string> extrude_gcode(const nlohmann::json& body);
// {"factor": 75..125 (or 0.75..1.25)} → M221 S…; {"factor": 50..200 (or 0.5..2)} → M220 S….
std::string flowrate_gcode(const nlohmann::json& factor);
std::string feedrate_gcode(const nlohmann::json& factor);
// {"x", "y", "z", "absolute", "speed"}: relative moves within the bed's size, absolute ones
// within its volume (origin at a corner or the centre, as the profile says). Relative axes of
// 0 are left out; none to send: empty.
std::vector<std::string> jog_gcode(const nlohmann::json& body, const core::PrinterProfile& profile);
// {"axes": ["x", "y", "z"]} → G28 X0 Y0 Z0.
std::vector<std::string> home_gcode(const nlohmann::json& body);

}  // namespace salient::server
