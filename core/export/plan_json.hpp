// The plan format's one writer and one reader (docs/plan-format.md): PlanDocument to JSON text and
// back, and the SegOpt report alone, as the daemon's job results embed it. nlohmann_json stays
// inside plan_json.cpp.
#pragma once

#include <string>
#include <string_view>

#include "core/export/plan_document.hpp"

namespace salient::core {

// The document as JSON ("format": "salient-plan", "version": 1), keys sorted, `indent` spaces
// deep (-1: one line), with a final newline when indented. Invalid UTF-8 in names is replaced.
std::string plan_json(const PlanDocument& plan, int indent = 2);

// A SegOpt report as the "segmentation" object of a plan (and of a job's result).
std::string segmentation_json(const SegmentationReport& report, int indent = -1);

// Estimated minutes against the uniform baselines as the "times" object of a plan (and of a job's
// result).
std::string times_json(const PlanTimes& times, int indent = -1);

// Reads a plan written by plan_json, or by `salient plan -o` before the format had a version (the
// same fields, no "format"). Throws InputError naming `name` and the field at fault; a newer
// version or another format is refused saying which it is. The SegOpt report is not read back
// (nothing here needs it): `segmentation` stays empty.
PlanDocument read_plan_json(std::string_view text, const std::string& name);

}  // namespace salient::core
