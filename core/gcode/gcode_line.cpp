// G-code line parsing: the subset of RS-274 that 3D-printer firmware reads (letters, numbers,
// ';' comments, '(…)' comments, N line numbers and *checksums).
#include "core/gcode/gcode_line.hpp"

#include <cctype>
#include <charconv>

namespace salient::core {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

}  // namespace

GcodeLine parse_gcode_line(std::string_view line, GcodeError& error) {
  error = GcodeError::none;
  GcodeLine out;
  const auto semi = line.find(';');
  if (semi != std::string_view::npos) {
    out.comment = trim(line.substr(semi + 1));
    line = line.substr(0, semi);
  }
  const auto star = line.find('*');
  if (star != std::string_view::npos) line = line.substr(0, star);
  std::size_t i = 0;
  while (i < line.size()) {
    const char c = line[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (c == '(') {  // inline comment
      const auto close = line.find(')', i);
      i = close == std::string_view::npos ? line.size() : close + 1;
      continue;
    }
    const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (letter < 'A' || letter > 'Z') {
      error = GcodeError::bad_word;
      return out;
    }
    ++i;
    std::size_t end = i;
    while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end])) &&
           !std::isalpha(static_cast<unsigned char>(line[end])) && line[end] != '(')
      ++end;
    std::string_view num = line.substr(i, end - i);
    i = end;
    if (num.empty()) {
      // "G28 X" (home X): a bare axis letter is a flag.
      if (out.letter && letter != 'N') out.present |= 1u << (letter - 'A');
      continue;
    }
    if (num.front() == '+') num.remove_prefix(1);
    double value = 0;
    auto [ptr, ec] = std::from_chars(num.data(), num.data() + num.size(), value);
    if (ec != std::errc() || ptr != num.data() + num.size()) {
      error = GcodeError::bad_number;
      return out;
    }
    if (letter == 'N' && !out.letter) continue;  // line number
    if (!out.letter && (letter == 'G' || letter == 'M' || letter == 'T')) {
      out.letter = letter;
      out.number = static_cast<int>(value);
      if (letter == 'T') out.values['T' - 'A'] = value;
      continue;
    }
    out.values[letter - 'A'] = value;
    out.present |= 1u << (letter - 'A');
  }
  return out;
}

}  // namespace salient::core
