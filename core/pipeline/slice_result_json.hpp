// A slice's figures as JSON: the one writer behind `salient slice --json` and a job's result, so
// that each figure has one name and one value wherever it is shown. nlohmann_json stays inside
// slice_result_json.cpp.
#pragma once

#include <string>

#include "core/common/setting_id.hpp"
#include "core/pipeline/slice_pipeline.hpp"

namespace salient::core {

// {"layers", "finest_layers", "saving" (1 − layers / finest_layers), "print_seconds" (the G-code's
// own estimate), "filament_mm", "stream", "error", "rsmd", "open_contours", "dropped_faces",
// "warnings" [{"code", "message"}], "saliency_method" (as the plan names it), "orientation",
// "segmentation", "times" (the time model's, as the plan's), "printer"}: keys sorted, `indent`
// spaces deep (-1: one line). Settings in warnings are named by `spell` (the front end's way).
std::string slice_result_json(const SliceResult& result, const std::string& printer_id,
                              const SettingSpeller& spell, int indent = -1);

}  // namespace salient::core
