// The plan documents a planning run hands on (core/export/plan_document): one builder for a single
// plan and one for a segmented plan, used by `salient plan` and by slice_model (the daemon's
// /plan), so that both write the same fields; and the SegOpt report alone, for `salient plan
// --segment --json`, the daemon's job results and the plan's "segmentation".
#pragma once

#include <string>

#include "core/export/plan_document.hpp"
#include "core/pipeline/planning_setup.hpp"
#include "core/segment/seg_opt.hpp"

namespace salient::core {

// `model`: the model's file name; `planner`: its name as given; `seconds`: time taken to plan.
PlanDocument plan_document(const PlanningSetup& setup, const std::string& model, const std::string& planner,
                           const PlanResult& result, const PlanTarget& target, double seconds);

// The printed layers are the regions' merged heights (printed_heights); E and RSMD those of all
// regions together (regions_error).
PlanDocument segmented_plan_document(const PlanningSetup& setup, const std::string& model,
                                     const std::string& planner, const SegOptResult& result, double seconds);

// `whole`: the profile the regions' cells are on.
SegmentationReport segmentation_report(const SegOptResult& result, const ZProfile& whole);

}  // namespace salient::core
