// InputError: formatting of the one-line message.
#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

std::string format(const std::string& source, const InputLocation& where, const std::string& message) {
  std::string out = source.empty() ? std::string("<input>") : source;
  if (where.line) {
    out += ':' + std::to_string(*where.line) + ": ";
  } else if (where.byte) {
    out += ": byte " + std::to_string(*where.byte) + ": ";
  } else {
    out += ": ";
  }
  return out + message;
}

}  // namespace

InputError::InputError(std::string source, InputLocation where, std::string message)
    : std::runtime_error(format(source, where, message)),
      source_(std::move(source)),
      where_(where),
      message_(std::move(message)) {}

}  // namespace salient::core
