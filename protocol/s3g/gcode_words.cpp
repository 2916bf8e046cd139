#include "protocol/s3g/gcode_words.hpp"

#include <cctype>
#include <charconv>
#include <climits>
#include <string>

namespace salient::protocol::s3g {
namespace {

bool is_space(char c) {
  return std::isspace(static_cast<unsigned char>(c)) != 0;
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

// gpx's normalize_word: the characters of the number after a letter at `i`, blanks dropped.
std::size_t read_number(std::string_view s, std::size_t i, std::string& out) {
  out.clear();
  while (i < s.size() && is_space(s[i])) ++i;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) out.push_back(s[i++]);
  const auto digits = [&] {
    for (; i < s.size() && (is_space(s[i]) || is_digit(s[i])); ++i)
      if (is_digit(s[i])) out.push_back(s[i]);
  };
  digits();
  if (i < s.size() && s[i] == '.') {
    out.push_back(s[i++]);
    digits();
  }
  return i;
}

// strtod and atoi of what normalize_word left, without their locale: "", "-" and "." are 0.
double to_double(std::string_view n) {
  if (!n.empty() && n[0] == '+') n.remove_prefix(1);
  double v = 0;
  const auto r = std::from_chars(n.data(), n.data() + n.size(), v);
  return r.ec == std::errc() ? v : 0.0;
}
int to_int(std::string_view n) {
  if (!n.empty() && n[0] == '+') n.remove_prefix(1);
  long long v = 0;
  const auto r = std::from_chars(n.data(), n.data() + n.size(), v);
  // atoi is (int)strtol: the low 32 bits, and strtol saturates at LONG_MIN/LONG_MAX.
  if (r.ec == std::errc::result_out_of_range)
    v = n[0] == '-' ? LLONG_MIN : LLONG_MAX;
  else if (r.ec != std::errc())
    v = 0;
  return static_cast<int>(v);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// gpx's comments: ";" to the end of the line, "(" to the last ")" when another "(" comes first, else
// to the first; a ";@" or "(@" macro ends the line without a comment. True when reading goes on.
bool read_comment(std::string_view text, std::size_t& i, GcodeWords& w) {
  const bool macro =
      i + 2 < text.size() && text[i + 1] == '@' && std::isalpha(static_cast<unsigned char>(text[i + 2]));
  if (macro) return false;
  if (text[i] == ';') {
    w.comment = std::string(trim(text.substr(i + 1)));
    w.flag |= word::COMMENT;
    return false;
  }
  const std::size_t open = text.find('(', i + 1);
  std::size_t close = text.find(')', i + 1);
  if (open != std::string_view::npos && close != std::string_view::npos && open < close)
    close = text.rfind(')');
  w.flag |= word::COMMENT;
  if (close == std::string_view::npos) {
    w.comment = std::string(trim(text.substr(i + 1)));
    return false;
  }
  w.comment = std::string(trim(text.substr(i + 1, close - i - 1)));
  i = close + 1;
  return true;
}

}  // namespace

GcodeWords parse_gcode_words(std::string_view text) {
  GcodeWords w;
  std::size_t i = 0;
  std::string number;
  while (i < text.size() && is_space(text[i])) ++i;
  if (i < text.size() && (text[i] == 'N' || text[i] == 'n')) i = read_number(text, i + 1, number);
  while (i < text.size()) {
    if (!std::isalpha(static_cast<unsigned char>(text[i]))) {
      if ((text[i] == ';' || text[i] == '(') && read_comment(text, i, w)) continue;
      break;  // '*' (checksum), the end of a comment, or what gpx refuses
    }
    const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text[i])));
    i = read_number(text, i + 1, number);
    double* value = nullptr;
    int* integer = nullptr;
    unsigned bit = 0;
    switch (letter) {
      case 'X':
        value = &w.x, bit = word::X;
        break;
      case 'Y':
        value = &w.y, bit = word::Y;
        break;
      case 'Z':
        value = &w.z, bit = word::Z;
        break;
      case 'A':
        value = &w.a, bit = word::A;
        break;
      case 'B':
        value = &w.b, bit = word::B;
        break;
      case 'E':
        value = &w.e, bit = word::E;
        break;
      case 'F':
        value = &w.f, bit = word::F;
        break;
      case 'P':
        value = &w.p, bit = word::P;
        break;
      case 'R':
        value = &w.r, bit = word::R;
        break;
      case 'S':
        value = &w.s, bit = word::S;
        break;
      case 'G':
        integer = &w.g, bit = word::G;
        break;
      case 'M':
        integer = &w.m, bit = word::M;
        break;
      case 'T':
        integer = &w.t, bit = word::T;
        break;
      default:
        continue;  // gpx warns and reads on
    }
    if (value) *value = to_double(number);
    if (integer) *integer = to_int(number);
    w.flag |= bit;
  }
  return w;
}

}  // namespace salient::protocol::s3g
