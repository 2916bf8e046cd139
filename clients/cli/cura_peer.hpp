// CuraEngine as a peer planner: slices the placed model with Cura's adaptive layers (CuraEngine's
// own command line, Debian's `cura-engine` with the definitions of `cura`) and returns its layers.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/export/plan_file.hpp"
#include "core/mesh/mesh.hpp"

namespace salient::cli {

struct CuraSettings {
  double min_layer = 0.1, max_layer = 0.4;  // α, ᾱ: Cura's layer_height ± its variation
  double first_layer = 0.2;                 // layer_height_0, fixed as in Cura
  double step = 0.01;                       // adaptive_layer_height_variation_step: our grid
};

struct CuraPlan {
  core::PlanFile layers;  // read back from its G-code, ;LAYER: and extrusion Z
  double seconds = 0;     // CuraEngine's run, wall clock
  std::string command;    // as run, for the record
};

// Where CuraEngine and fdmprinter.def.json are installed, or an empty optional (then `why` says
// what is missing).
std::optional<CuraPlan> cura_adaptive_plan(const core::Mesh& placed, const CuraSettings& settings,
                                           const std::filesystem::path& work_dir, std::string& why);

}  // namespace salient::cli
