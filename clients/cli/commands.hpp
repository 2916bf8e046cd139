// The `salient` subcommands: each registers itself on the app and runs when chosen.
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace salient::cli {

// Registers a subcommand; returns the action to run when the user chose it (exit status).
using CommandAction = std::function<int()>;

void add_info_command(CLI::App& app, CommandAction& action);
void add_plan_command(CLI::App& app, CommandAction& action);
void add_compare_command(CLI::App& app, CommandAction& action);
void add_saliency_command(CLI::App& app, CommandAction& action);

}  // namespace salient::cli
