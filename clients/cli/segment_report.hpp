// How the CLI shows a SegOpt result: text lines and JSON.
#pragma once

#include <nlohmann/json.hpp>

#include "core/segment/seg_opt.hpp"

namespace salient::cli {

// "segmentation: cut: 2 regions …" and one line per region.
void print_segmentation(const core::SegOptResult& result, const core::ZProfile& whole);

nlohmann::json segmentation_json(const core::SegOptResult& result, const core::ZProfile& whole);

}  // namespace salient::cli
