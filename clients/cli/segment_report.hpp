// How the CLI shows a SegOpt result as text (its JSON is core/export/plan_json's, as the daemon's).
#pragma once

#include "core/segment/seg_opt.hpp"

namespace salient::cli {

// "segmentation: cut: 2 regions …" and one line per region.
void print_segmentation(const core::SegOptResult& result, const core::ZProfile& whole);

}  // namespace salient::cli
