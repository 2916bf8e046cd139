// G-code from toolpaths: Marlin (default), RepRap or Sailfish flavour, PrusaSlicer and Cura
// layer comments, M73 progress, retraction on travel, fan and minimum layer time; with the
// profile's arc_fitting, G2/G3 arcs (not for Sailfish). The header carries PrusaSlicer's
// thumbnail blocks and the metadata comments PrusaSlicer's viewer, OctoPrint and Moonraker read.
#pragma once

#include <string>
#include <vector>

#include "core/common/progress.hpp"
#include "core/gcode/gcode_thumbnail.hpp"
#include "core/gcode/stream_demand.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/toolpath/toolpath.hpp"

namespace salient::core {

struct GcodeSettings {
  bool relative_e = true;                  // M83 (ignored for Sailfish, which takes absolute E)
  double retract_min_travel = 2.0;         // mm: shorter travels do not retract
  double min_layer_time = 8.0;             // s: slower layers below it…
  double min_print_speed = 10.0;           // mm/s: …but never slower than this (PrusaSlicer's default too)
  int fan_from_layer = 1;                  // 0-based index of the first layer with the part fan on
  std::vector<std::string> summary;        // lines for the header (the plan: planner, layers, saving…)
  std::vector<GcodeThumbnail> thumbnails;  // written into the header, in this order
  const CancelToken* cancel = nullptr;     // a job's: checked every few layers and while estimating
};

struct GcodeResult {
  std::string text;
  double seconds = 0;  // our estimate of the whole file
  double filament_mm = 0;
  std::size_t layers = 0;
  StreamDemand stream;  // of the layers' commands, over a link at the printer's baud rate
};

// Throws InputError when a path leaves the printer's bed or the model is taller than it.
GcodeResult write_gcode(const std::vector<LayerToolpaths>& layers, const PrinterProfile& printer,
                        const GcodeSettings& settings);

// Slic3r's flow model: the cross-section of an extruded line of width w and height h is a
// rectangle with semicircular ends, (w − h)·h + π·h²/4 (mm²).
double extrusion_area(double width, double height);

// PrusaSlicer's duration text (get_time_dhms): "1d 2h 3m 4s", leading zero units left out ("3m 4s").
std::string time_dhms(double seconds);

}  // namespace salient::core
