// The `salient` subcommands: each registers itself on the app and runs when chosen.
#pragma once

#include <functional>
#include <string>

#include "core/printer/printer_profile.hpp"

namespace CLI {
class App;
}

namespace salient::cli {

// A built-in printer id or a .toml path; throws InputError naming --printer otherwise.
core::PrinterProfile resolve_printer(const std::string& spec);

// Registers a subcommand; returns the action to run when the user chose it (exit status).
using CommandAction = std::function<int()>;

void add_info_command(CLI::App& app, CommandAction& action);
void add_plan_command(CLI::App& app, CommandAction& action);
void add_compare_command(CLI::App& app, CommandAction& action);
void add_saliency_command(CLI::App& app, CommandAction& action);
void add_estimate_command(CLI::App& app, CommandAction& action);
void add_slice_command(CLI::App& app, CommandAction& action);
void add_export_command(CLI::App& app, CommandAction& action);
void add_export_x3g_command(CLI::App& app, CommandAction& action);
void add_print_command(CLI::App& app, CommandAction& action);
// submit, jobs, watch, printers: clients of a running salientd.
void add_client_commands(CLI::App& app, CommandAction& action);
// keys list|create|revoke|requests|approve|deny: salientd's API keys and app key requests.
void add_keys_command(CLI::App& app, CommandAction& action);
// doctor: why it does not connect (doctor.hpp).
void add_doctor_command(CLI::App& app, CommandAction& action);

}  // namespace salient::cli
