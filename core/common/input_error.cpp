// InputError: formatting of the one-line message.
#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

std::string format(const std::string& source, const InputLocation& where, const std::string& message) {
  std::string out = source.empty() ? std::string("<input>") : source;
  if (where.line) {
    out.append(":").append(std::to_string(*where.line)).append(": ");
  } else if (where.byte) {
    out.append(": byte ").append(std::to_string(*where.byte)).append(": ");
  } else {
    out += ": ";
  }
  return out + message;
}

std::string bare_key(SettingId id) {
  return std::string(setting_key(id));
}

}  // namespace

InputError::InputError(std::string source, InputLocation where, std::string message)
    : std::runtime_error(format(source, where, spell_settings(message, bare_key))),
      source_(std::move(source)),
      where_(where),
      message_(std::move(message)) {}

InputError::InputError(SettingId setting, std::string message)
    : std::runtime_error(format(bare_key(setting), {}, spell_settings(message, bare_key))),
      source_(bare_key(setting)),
      message_(std::move(message)),
      setting_(setting) {}

std::string InputError::spelled(const SettingSpeller& spell) const {
  return format(setting_ ? spell(*setting_) : source_, where_, spell_settings(message_, spell));
}

}  // namespace salient::core
