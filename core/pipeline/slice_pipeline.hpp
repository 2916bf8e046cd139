// slice_model: the whole chain from a model file to G-code — load, place on the printer's bed,
// saliency, plan, toolpaths (and support), G-code — as the CLI's `slice` and the daemon's jobs
// run it. Phases reported through RunContext, in order: orient (with up "auto"), load, saliency
// (or lee05), profile, plan (then the planner's own name) or segment (SegOpt, with its planners'
// names inside), toolpaths, gcode. The daemon maps them onto job phases (server/jobs/job_progress).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/common/progress.hpp"
#include "core/export/plan_document.hpp"
#include "core/gcode/gcode_writer.hpp"
#include "core/gcode/stream_demand.hpp"
#include "core/orient/orientation.hpp"
#include "core/pipeline/planning_setup.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/pipeline/slice_warning.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/segment/seg_opt.hpp"
#include "core/toolpath/support_generator.hpp"
#include "core/toolpath/toolpath_generator.hpp"

namespace salient::core {

struct SliceSettings {
  PlanOptions plan;
  bool min_layer_from_printer = true, max_layer_from_printer = true;  // else plan.min_layer/max_layer
  ToolpathSettings toolpaths;
  bool combine_infill = true;  // sparse infill once for thin layers under the printer's thickest
  bool support = false;
  SupportSettings support_settings;
  bool artefacts = false;  // also make the plot, the 3MF and the saliency PLY (SliceResult)
};

struct SliceResult {
  std::string gcode;
  std::vector<double> z;  // layer tops, mm
  int layers = 0, finest_layers = 0;
  double error = 0, rsmd = 0;
  double print_seconds = 0, filament_mm = 0;
  StreamDemand stream;            // the G-code's busiest second against the printer's serial link
  std::size_t open_contours = 0;  // left out: holes in the mesh wider than toolpaths.max_gap
  std::size_t dropped_faces = 0;  // left out of the layer profile: zero or non-finite area
  std::string model_name;
  // What the owner should know before printing, in the order found: the model's size as placed,
  // faces and contours left out, a G-code denser than the serial link. The fields above hold
  // the counts; these say them, each with its fix.
  std::vector<SliceWarning> warnings;
  // With SliceSettings::artefacts: the plan's plot (SVG), the placed model with the plan as
  // PrusaSlicer's layer-height profile (3MF), and the saliency as vertex quality and colour (PLY).
  std::string plot_svg, model_3mf, saliency_ply;
  std::optional<OrientationReport> orientation;  // with --up auto: the candidates and the choice
  std::optional<SegOptResult> segmentation;      // with plan.segment: the regions and the decision
  PlanDocument plan;  // the plan as `salient plan -o` writes it (with plan.segment, as --segment -o)
};

// The checks slice_model makes before it loads anything, with the printer's layer limits where
// `settings` take them from it: for a front end that refuses bad settings at once (a job's 400).
// Throws InputError naming the setting at fault.
void check_slice_settings(const SliceSettings& settings, const PrinterProfile& printer);

// The time model's printer, toolpath and G-code values (its calibrated factors stay).
TimeModelParams time_model_params(const PrinterProfile& printer, const ToolpathSettings& toolpaths,
                                  const GcodeSettings& gcode);

// The toolpath and support settings slice_model prints with on `printer`: `settings`' own with
// the printer's small-section solid infill, G-code resolution and (with combine_infill) its
// thickest layer for combined sparse infill. Whatever times a plan for `printer` (plan --segment,
// compare's SegOpt rows) uses these, so that it times what slice prints.
RegionSliceSettings region_slice_settings(const SliceSettings& settings, const PrinterProfile& printer);

// Throws InputError naming the setting or file at fault, Cancelled when run.cancel fires; also
// when nothing of the model would print (lower than the first layer) and, without support, when
// the printed layers do not stand on the bed (an open mesh's lowest sections left out).
// plan.mesh.up = "auto" first chooses the orientation (core/pipeline/auto_orient, phase "orient").
SliceResult slice_model(SliceSettings settings, const PrinterProfile& printer, const RunContext& run);

}  // namespace salient::core
