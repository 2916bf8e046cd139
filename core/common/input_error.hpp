// InputError: bad input from outside (a broken file, an impossible setting), with where it is.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/common/setting_id.hpp"

namespace salient::core {

// Where in an input a problem sits: a 1-based line of a text file or a byte offset of a binary
// one (or neither, for a problem with the input as a whole).
struct InputLocation {
  std::optional<std::uint64_t> line;
  std::optional<std::uint64_t> byte;

  static InputLocation at_line(std::uint64_t n) { return {n, std::nullopt}; }
  static InputLocation at_byte(std::uint64_t n) { return {std::nullopt, n}; }
};

// Thrown by core functions for input they cannot accept. what() reads
// "SOURCE:LINE: message", "SOURCE: byte N: message" or "SOURCE: message", so that a user can
// find the problem; the CLI prints it as one line, the daemon returns it with a 4xx status.
// A setting at fault is a SettingId, not a flag: the source may be one, and the message may name
// others as "{key}" placeholders (setting_id.hpp), which each front end spells (spelled());
// what() spells them as bare keys ("grid: 0.03 mm does not divide min_layer 0.1 …").
class InputError : public std::runtime_error {
 public:
  InputError(std::string source, InputLocation where, std::string message);
  InputError(SettingId setting, std::string message);

  const std::string& source() const { return source_; }
  const InputLocation& where() const { return where_; }
  const std::string& message() const { return message_; }  // with its placeholders
  const std::optional<SettingId>& setting() const { return setting_; }
  // The one-line form with every setting named by `spell`.
  std::string spelled(const SettingSpeller& spell) const;

 private:
  std::string source_;
  InputLocation where_;
  std::string message_;
  std::optional<SettingId> setting_;
};

}  // namespace salient::core
