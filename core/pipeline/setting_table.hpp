// The settings table: every slicing setting declared once — JSON key, CLI flag, type, unit,
// range, default, help and the member it sets. The CLI's options (clients/cli/setting_options),
// a job's settings and their canonical form (server/jobs/job_settings) and the README's list are
// all built from it; tests/clients/cli/setting_options_test.cpp walks it against each of them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "core/common/setting_id.hpp"
#include "core/pipeline/slice_pipeline.hpp"

namespace salient::core {

// Everything a slice is asked with: the printer (a built-in id, or a .toml path in the CLI) and
// the core's settings. The defaults are the table's defaults.
struct Settings {
  std::string printer = "generic-i3";
  SliceSettings slice;
};

enum class SettingType {
  number,   // double
  integer,  // std::int64_t (a job must give a whole number)
  flag,     // bool
  text,     // std::string
  choice,   // std::string, one of choices()
};

// The value of one setting, of its type (choice: the name).
using SettingValue = std::variant<bool, std::int64_t, double, std::string>;

// When a setting is in a job's canonical form. Jobs with equal canonical settings share results,
// so a setting added later must be `when_changed`: older jobs keep their form.
enum class InCanonical {
  always,        // every job, defaults included
  when_given,    // only when set (its default is "unset", or "the printer's")
  when_changed,  // only when it differs from the default
};

// Which `salient` commands take a setting (bits). compare takes plan's options but --planner.
enum SettingCommand : unsigned { for_plan = 1, for_compare = 2, for_slice = 4 };
inline constexpr unsigned for_planning = for_plan | for_compare | for_slice;

struct Setting {
  SettingId id;
  std::string_view key{};   // a job's JSON key
  std::string_view flag{};  // the CLI's option
  SettingType type = SettingType::number;
  std::string_view unit{};  // "mm", "°" or empty
  double min = 0, max = 0;  // number, integer: the accepted range, inclusive (a job's check)
  std::string_view help{};
  std::string_view member{};  // what it sets in Settings
  unsigned commands = for_planning;
  InCanonical canonical = InCanonical::always;
  std::optional<SettingId>
      only_with{};                    // applies only with this flag on (else left out of the canonical form)
  std::vector<SettingId> excludes{};  // may not be given with these
  bool cli_checks = false;    // the CLI checks range or choice while parsing (else core refuses it later)
  bool from_printer = false;  // in slice and jobs the default is the printer profile's
  std::string_view not_a_job_setting{};                           // why not (empty: it is one)
  std::optional<SettingValue> (*get)(const Settings&) = nullptr;  // nullopt: not given
  void (*set)(Settings&, const SettingValue&) = nullptr;          // throws InputError naming it
  const std::vector<std::string_view>& (*choices)() = nullptr;    // choice: the name table
};

// In the order of SettingId.
const std::vector<Setting>& setting_table();
const Setting& setting(SettingId id);
const Setting* setting_by_key(std::string_view key);  // nullptr for an unknown key

// "0.4", "exact", "true"; the value `plan` uses for a from_printer setting; empty when unset.
std::string value_text(const SettingValue& value);
std::string default_text(const Setting& setting);

// The settings of `settings` that its canonical form holds, in table order (the caller sorts).
std::vector<std::pair<const Setting*, SettingValue>> canonical_values(const Settings& settings);

// The README's list of settings (a Markdown table), between its "settings table" markers.
std::string settings_markdown();

}  // namespace salient::core
