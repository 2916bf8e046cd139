// Fuzz target for the G-code reader and time estimator, and the printer-profile parser: any
// bytes end in a result or an InputError.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/common/input_error.hpp"
#include "core/gcode/time_estimator.hpp"
#include "core/printer/printer_profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      const auto e = salient::core::estimate_gcode(text, "fuzz.gcode");
      if (!(e.seconds >= 0) && !std::isnan(e.seconds)) std::abort();
    } else {
      salient::core::parse_printer_profile(text, "fuzz.toml");
    }
  } catch (const salient::core::InputError&) {
  }
  return 0;
}
