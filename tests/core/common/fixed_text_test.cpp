#include "core/common/fixed_text.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

using salient::core::fixed_text;

namespace {
std::string printf_fixed(double v, int decimals) {
  char buf[400];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
}  // namespace

TEST_CASE("fixed_text writes what printf writes in the C locale, for any double and decimal count") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> exponent(-12, 12);
  for (int i = 0; i < 20000; ++i) {
    const double v = (rng() % 2 ? -1 : 1) * std::pow(10.0, exponent(rng));
    const int d = static_cast<int>(rng() % 10);
    REQUIRE(fixed_text(v, d) == printf_fixed(v, d));
  }
  CHECK(fixed_text(0.125, 2) == printf_fixed(0.125, 2));  // ties round as printf does
  CHECK(fixed_text(-0.0, 3) == "-0.000");
  CHECK(fixed_text(std::numeric_limits<double>::max(), 2) ==
        printf_fixed(std::numeric_limits<double>::max(), 2));
}

TEST_CASE("fixed_text holds the decimal count to 0..20") {
  CHECK(fixed_text(1.5, -3) == "2");
  CHECK(fixed_text(1.0, 99) == "1.00000000000000000000");
}
