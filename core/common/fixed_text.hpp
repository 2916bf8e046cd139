// fixed_text: a number as text with a fixed count of decimals, locale-free (SVG, 3MF attributes).
#pragma once

#include <cstdio>
#include <string>

namespace salient::core {

inline std::string fixed_text(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace salient::core
