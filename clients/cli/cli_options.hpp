// The options several commands share, bound to the core's option structs.
#pragma once

#include "core/pipeline/planning_setup.hpp"

namespace CLI {
class App;
}

namespace salient::cli {

// MODEL, --up, --height and --scale.
void add_mesh_options(CLI::App& command, core::MeshOptions& options);
// The mesh options, the planning options and --json.
void add_plan_options(CLI::App& command, core::PlanOptions& options, bool& json);

}  // namespace salient::cli
