// fixed_text: a number as text with a fixed count of decimals, locale-free (SVG, 3MF attributes):
// std::to_chars ignores the C locale, where snprintf would write "0,5" under a German one.
#pragma once

#include <charconv>
#include <string>

namespace salient::core {

// `decimals` is held to 0..20, so that the longest double (1.8e308, 309 digits) always fits.
inline std::string fixed_text(double v, int decimals) {
  char buf[400];
  const int d = decimals < 0 ? 0 : decimals > 20 ? 20 : decimals;
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, d);
  return std::string(buf, r.ptr);
}

}  // namespace salient::core
