// LayerTimeModel: the estimated printing time of any candidate layer [z_i, z_j] in O(1), from a
// pre-pass over the mesh's sections on the planning grid — what the `time` objective minimises
// (ALGORITHMS.md §4, "Optimise time").
//
// A layer's paths have the line width w whatever its height h, so their length hardly depends
// on h: walls are walls × the section's perimeter; solid skin is its area / spacing, with
// spacing w − h(1 − π/4) (the toolpath generator's flow model); sparse infill the same at the
// infill density, printed once per group of thin layers up to ᾱ where infill is combined, so
// it costs a share h/ᾱ of a layer. Skin lies where a surface is within the skin thickness (in
// mm) above or below: the horizontal projection of the up-facing surface just above the layer
// and of the down-facing surface just below it is that area. Seconds are lengths over the
// print speed, each role with a factor for acceleration and corners, plus an overhead per
// layer (Z move, retraction), one per infill line (the stop at each end), travel in proportion
// to the section's size, and the G-code writer's minimum layer time. The factors are calibrated against
// estimate_gcode on real G-code (tests/bench/time_model_bench, BENCHMARKS.md "Step 11 — minutes").
#pragma once

#include <memory>
#include <vector>

#include "core/mesh/mesh.hpp"
#include "core/slicing/layer_plan.hpp"
#include "core/slicing/z_profile.hpp"

namespace salient::core {

struct TimeModelParams {
  // The printer's (PrinterProfile) and the toolpaths' (ToolpathSettings) values; the defaults
  // are generic-i3's and the toolpath defaults.
  double print_speed = 50, first_layer_speed = 20, travel_speed = 150;  // mm/s
  double line_width = 0.45;                                             // mm
  int walls = 2;
  double infill_density = 0.2;
  double top_thickness = 0.8, bottom_thickness = 0.8;  // mm
  double combine_infill_up_to = 0.3;                   // mm; 0: sparse infill on every layer
  double min_layer_time = 8, min_print_speed = 10;     // s, mm/s (GcodeSettings)
  // Calibrated (see the file comment): seconds per layer, per infill line, and the factor by
  // which each role's length/speed underestimates its time.
  // Travel is the section's size √area times a factor, and another where sparse infill is
  // combined (each thin layer then prints the slivers of its own sparse area, all over).
  double layer_overhead = 1.2, line_overhead = 0.06;
  double wall_factor = 1.25, solid_factor = 1.0, sparse_factor = 1.0;
  double travel_factor = 5, combined_travel_factor = 25;
};

// What a layer prints, as the model sees it (mm of path, count of infill lines).
struct LayerFeatures {
  double wall_length = 0, solid_length = 0, sparse_length = 0, infill_lines = 0;
  double section_area = 0;  // mm²
  bool combined = false;    // its sparse infill is shared with neighbours (printed on one of them)
  bool first = false;       // the printer's first layer (its own speed)
};

class LayerTimeModel {
 public:
  // `mesh` placed (lowest point at z = 0), `profile` its grid. Throws nothing on odd meshes:
  // open or self-intersecting sections only make the estimate rougher.
  LayerTimeModel(const Mesh& mesh, const ZProfile& profile, const TimeModelParams& params = {});

  // The same model for the cells [first, last) seen from z = 0 (a window of the profile, as
  // ZProfile::window): layers are costed where they lie in the whole model.
  LayerTimeModel window(int first, int last) const;

  const TimeModelParams& params() const { return params_; }
  int cells() const { return last_ - first_; }

  LayerFeatures features(int i, int j) const;
  double layer_seconds(int i, int j) const;  // the layer spanning cells [i, j)
  double seconds(const LayerPlan& plan) const;

 private:
  struct Sections;  // per cell of the whole model: perimeter, area, up/down projected areas
  LayerTimeModel() = default;
  std::shared_ptr<const Sections> sections_;
  TimeModelParams params_;
  double grid_ = 0.01, height_ = 0;  // the whole model's
  int first_ = 0, last_ = 0;         // this window's cells of the whole model
};

}  // namespace salient::core
