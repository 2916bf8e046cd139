// GcodeLine: one G-code line split into its command and parameter words.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace salient::core {

struct GcodeLine {
  char letter = 0;           // 'G', 'M', 'T' or 0 for a line with no command
  int number = -1;           // 1 for G1, 104 for M104
  std::string_view comment;  // after ';', trimmed
  std::array<double, 26> values{};
  std::uint32_t present = 0;  // bit i set: parameter 'A' + i given

  bool has(char p) const { return present & (1u << (p - 'A')); }
  double get(char p, double fallback = 0) const { return has(p) ? values[p - 'A'] : fallback; }
  bool is(char l, int n) const { return letter == l && number == n; }
};

enum class GcodeError { none, bad_number, bad_word };

// Parses one line (without its terminator). Words are a letter and a number ("X10.5", "S200");
// a line number word N and a *checksum are dropped; `error` says why a line could not be read.
GcodeLine parse_gcode_line(std::string_view line, GcodeError& error);

}  // namespace salient::core
