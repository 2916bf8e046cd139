// The options several commands share, bound to the core's option structs.
#pragma once

#include "clients/cli/setting_options.hpp"
#include "core/orient/orientation.hpp"
#include "core/pipeline/planning_setup.hpp"

namespace CLI {
class App;
}

namespace salient::cli {

// MODEL, --up, --height and --scale. `allow_auto`: --up auto (commands that slice).
void add_mesh_options(CLI::App& command, core::MeshOptions& options, bool allow_auto = false);
// MODEL (into settings.slice.plan.mesh.model), the settings table's options for `command`
// (core::for_plan, for_compare or for_slice) and --json. Apply the result to `settings` in the action.
SettingOptions add_plan_options(CLI::App& cmd, core::Settings& settings, bool& json, unsigned command);

// --up auto for commands that do not slice: chooses as `slice` would, scoring time on the
// generic-i3 profile (plan options from `plan` when given), prints the candidates unless
// `quiet`, and sets mesh.up to the chosen direction.
void resolve_auto_up(core::MeshOptions& mesh, const core::PlanOptions* plan, bool quiet);

// What --up auto chose: one line per candidate with its scores.
void print_orientation(const core::OrientationReport& report);

}  // namespace salient::cli
