// --up auto: slices the model in each of its candidate orientations (core/orient: its bases, then
// the paper's three axes) with our own toolpaths and support, as the paper scores time with
// support (§6), and picks the best score. StaS's contact is measured at print scale (half the
// printer's first layer). Phase "orient" is reported, fraction over the slices.
#pragma once

#include "core/common/progress.hpp"
#include "core/orient/orientation.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/printer/printer_profile.hpp"

namespace salient::core {

// `settings.plan.mesh.up` is ignored. With a target height the candidates are compared at one
// scale: the one that gives the tallest candidate that height (OrientationReport::scale, which
// the caller keeps for the print). Throws InputError, Cancelled.
OrientationReport choose_orientation(const SliceSettings& settings, const PrinterProfile& printer,
                                     const RunContext& run);

}  // namespace salient::core
