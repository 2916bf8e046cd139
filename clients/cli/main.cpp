// `salient`: the command-line tool over salient's core and a client of salientd.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "clients/cli/commands.hpp"
#include "clients/cli/setting_options.hpp"
#include "core/common/input_error.hpp"
#include "protocol/serial/transport.hpp"

int main(int argc, char** argv) {
  CLI::App app{"salient: saliency-preserving adaptive slicing for FDM printers"};
  app.set_version_flag("--version", std::string("salient ") + SALIENT_VERSION);
  app.require_subcommand(1);
  salient::cli::CommandAction action;
  salient::cli::add_info_command(app, action);
  salient::cli::add_plan_command(app, action);
  salient::cli::add_compare_command(app, action);
  salient::cli::add_saliency_command(app, action);
  salient::cli::add_estimate_command(app, action);
  salient::cli::add_slice_command(app, action);
  salient::cli::add_export_command(app, action);
  salient::cli::add_export_x3g_command(app, action);
  salient::cli::add_print_command(app, action);
  salient::cli::add_client_commands(app, action);
  salient::cli::add_keys_command(app, action);
  salient::cli::add_doctor_command(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return action ? action() : 0;
  } catch (const salient::protocol::serial::LinkError& e) {
    std::fprintf(stderr, "salient: error: %s\n", e.what());
    return 4;
  } catch (const salient::core::InputError& e) {  // settings spelled as flags: "--grid"
    std::fprintf(stderr, "salient: error: %s\n", e.spelled(salient::cli::cli_flag).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "salient: internal error: %s\n", e.what());
    return 3;
  }
}
