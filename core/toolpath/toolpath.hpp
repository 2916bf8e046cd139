// Toolpaths: what the nozzle extrudes on each layer, before it becomes G-code.
#pragma once

#include <vector>

#include "core/geometry/polygon_ops.hpp"

namespace salient::core {

enum class ExtrusionRole { skirt, support, external_perimeter, perimeter, solid_infill, sparse_infill };

struct ExtrusionPath {
  Polyline points;
  bool closed = false;  // a loop: the last point joins the first
  double width = 0.45;  // mm
  ExtrusionRole role = ExtrusionRole::perimeter;
  double height = 0;  // mm of material it lays down; 0: the layer's height (more where infill is combined)

  double length() const;
};

struct LayerToolpaths {
  double z_bottom = 0, z_top = 0;  // mm; the nozzle prints at z_top
  std::vector<ExtrusionPath> paths;
  // Areas (mm²) the paths are meant to fill, for checks: walls, solid infill, sparse infill.
  double wall_area = 0, solid_area = 0, sparse_area = 0;
  std::size_t open_chains = 0;  // section chains left open (holes in the mesh)
  bool filled = false;          // its section was all open chains: taken from the layers around it
  Polygons region;              // the layer's outline (travel inside it needs no retraction)
  Polygons sparse;              // where its sparse infill goes (filled in a second pass)

  double height() const { return z_top - z_bottom; }
};

struct ToolpathSettings {
  double line_width = 0.45;  // mm
  int walls = 2;
  double top_thickness = 0.8;     // mm of solid skin under a top surface, whatever the layer heights
  double bottom_thickness = 0.8;  // mm of solid skin over a bottom surface
  double infill_density = 0.2;    // 0..1, rectilinear
  double skirt_distance = 3;      // mm from the first layer's outline; 0 for no skirt
  double max_gap = 3.0;           // mm: open section chains closed up to this gap
  // Sections are simplified within this deviation (mm; the printer's gcode_resolution) before the
  // walls are inset, so walls, skins and infill outlines follow it; 0 keeps every mesh vertex.
  double resolution = 0.0125;
  // Sparse infill is printed once for as many thin layers as fit under this height (mm), where
  // all of them have sparse infill (Sabourin 1996's fast interior, the paper's solid option);
  // 0 prints it on every layer.
  double combine_infill_up_to = 0;
  // An island of sparse infill no larger than this (mm²) is filled solid instead, as PrusaSlicer's
  // solid_infill_below_area (a printer-profile value): a sparse grid in a small section holds
  // nothing up and prints as loose strands. 0 keeps every island sparse.
  double solid_infill_below_area = 0;
  // A region of a segmented plan: only this XY area of the mesh is printed (empty: all of it).
  Polygons clip;
};

}  // namespace salient::core
