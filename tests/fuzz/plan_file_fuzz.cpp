// Fuzz target for the plan-file readers (G-code layers, plan JSON, 3MF through the ZIP reader,
// PrusaSlicer's profile): any bytes end in strictly increasing positive tops or an InputError.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/common/input_error.hpp"
#include "core/export/plan_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const salient::core::PlanFile f = salient::core::parse_plan_file(bytes, "fuzz.plan");
    if (f.tops.empty() || f.tops.size() != f.lines.size()) std::abort();
    for (std::size_t i = 0; i < f.tops.size(); ++i)
      if (!(f.tops[i] > 0) || (i > 0 && !(f.tops[i] > f.tops[i - 1]))) std::abort();
  } catch (const salient::core::InputError&) {
  }
  return 0;
}
