// SettingOptions: the settings table's rows (core/pipeline/setting_table.hpp) as one command's
// CLI11 options, and the CLI's spelling of a setting ("--grid").
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/pipeline/setting_table.hpp"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace salient::cli {

// The option that sets `id`: "--grid".
std::string cli_flag(core::SettingId id);

class SettingOptions {
 public:
  SettingOptions() = default;
  // Adds, in table order, every setting that `command` (core::for_plan, …) takes.
  SettingOptions(CLI::App& app, unsigned command);

  // Writes the options given on the command line into `settings` (the others keep their
  // defaults). Throws InputError naming the setting, e.g. an unknown planner.
  void apply(core::Settings& settings) const;

 private:
  struct Bound;
  std::vector<std::shared_ptr<Bound>> bound_;  // shared: CLI11 holds their addresses
};

}  // namespace salient::cli
