// SliceWarning: something a slice finished with that its owner should know before printing
// (a model far too small or too large for the bed, holes left out), as one code and one message
// that every front end shows the same way: the CLI's "warning:" lines, a job's result.warnings[].
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.hpp"
#include "core/printer/printer_profile.hpp"

namespace salient::core {

struct SliceWarning {
  std::string code;     // stable, for programs: "model_tiny", "model_larger_than_bed", …
  std::string message;  // for people; settings as "{key}" placeholders (spell_settings)
};

// Sizes no one prints on purpose, as placed on `printer`'s bed (`placed`, mm): every side under
// a few millimetres (a file in metres, or of unit size, read as millimetres) or a side beyond
// the build volume. Each warning says the size and the fix ({height}, {scale}, the units).
std::vector<SliceWarning> model_size_warnings(const BoundingBox& placed, const PrinterProfile& printer,
                                              const std::string& model_name);

// Throws InputError (source `model_name`) when the placed model is lower than the fixed first
// layer (`first_layer`, mm): not even that layer would print in full.
void check_printable_height(const BoundingBox& placed, double first_layer, const std::string& model_name);

}  // namespace salient::core
