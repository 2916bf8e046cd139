// SettingOptions: CLI11 options bound to the settings table; values are applied after parsing, so
// that a bad one is refused with core's message, spelled with the flag.
#include "clients/cli/setting_options.hpp"

#include <CLI/CLI.hpp>
#include <cctype>

#include "core/common/input_error.hpp"

namespace salient::cli {

struct SettingOptions::Bound {
  const core::Setting* setting = nullptr;
  CLI::Option* option = nullptr;
  double number = 0;
  std::int64_t integer = 0;
  bool flag = false;
  std::string text;

  core::SettingValue value() const {
    switch (setting->type) {
      case core::SettingType::number:
        return number;
      case core::SettingType::integer:
        return integer;
      case core::SettingType::flag:
        return flag;
      case core::SettingType::text:
      case core::SettingType::choice:
        break;
    }
    return text;
  }
};

std::string cli_flag(core::SettingId id) {
  return std::string(core::setting(id).flag);
}

namespace {

std::string upper(std::string_view key) {
  std::string out(key);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string help_of(const core::Setting& s, unsigned command) {
  std::string help(s.help);
  if (!s.unit.empty()) help += " (" + std::string(s.unit) + ")";
  if (s.from_printer && (command & core::for_slice)) help += " (default: the printer profile's)";
  return help;
}

template <class Storage>
CLI::Option* add(CLI::App& app, const core::Setting& s, unsigned command, Storage& b) {
  const std::string flag(s.flag), help = help_of(s, command);
  CLI::Option* o = nullptr;
  switch (s.type) {
    case core::SettingType::number:
      o = app.add_option(flag, b.number, help);
      break;
    case core::SettingType::integer:
      o = app.add_option(flag, b.integer, help);
      break;
    case core::SettingType::flag:
      o = core::default_text(s) == "true" ? app.add_option(flag, b.flag, help)
                                          : app.add_flag(flag, b.flag, help);
      break;
    case core::SettingType::text:
    case core::SettingType::choice:
      o = app.add_option(flag, b.text, help);
      break;
  }
  const bool shows_default = s.type != core::SettingType::flag || core::default_text(s) == "true";
  if (shows_default && !(s.from_printer && (command & core::for_slice)))
    o->default_str(core::default_text(s));
  if (!s.cli_checks) return o;
  if (s.type == core::SettingType::number) o->check(CLI::Range(s.min, s.max));
  if (s.type == core::SettingType::integer)
    o->check(CLI::Range(static_cast<std::int64_t>(s.min), static_cast<std::int64_t>(s.max)));
  if (s.type == core::SettingType::choice)
    o->check(CLI::IsMember(std::vector<std::string>(s.choices().begin(), s.choices().end())));
  if (s.type == core::SettingType::text)
    o->check(CLI::Validator(
        [&s](std::string& v) -> std::string {
          core::Settings scratch;
          try {
            s.set(scratch, v);
          } catch (const core::InputError& e) {
            return core::spell_settings(e.message(), cli_flag);
          }
          return {};
        },
        upper(s.key)));
  return o;
}

}  // namespace

SettingOptions::SettingOptions(CLI::App& app, unsigned command) {
  for (const core::Setting& s : core::setting_table()) {
    if (!(s.commands & command)) continue;
    auto b = std::make_shared<Bound>();
    b->setting = &s;
    b->option = add(app, s, command, *b);
    bound_.push_back(std::move(b));
  }
  for (const auto& b : bound_)
    for (core::SettingId other : b->setting->excludes)
      for (const auto& c : bound_)
        if (c->setting->id == other) b->option->excludes(c->option);
}

void SettingOptions::apply(core::Settings& settings) const {
  for (const auto& b : bound_)
    if (b->option->count() > 0) b->setting->set(settings, b->value());
}

}  // namespace salient::cli
