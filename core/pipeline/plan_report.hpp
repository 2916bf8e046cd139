// The plan documents a planning run hands on (core/export/plan_document): one builder for a single
// plan and one for a segmented plan, used by `salient plan` and by slice_model (the daemon's
// /plan), so that both write the same fields; and the SegOpt report alone, for `salient plan
// --segment --json`, the daemon's job results and the plan's "segmentation".
#pragma once

#include <optional>
#include <string>

#include "core/export/plan_document.hpp"
#include "core/pipeline/planning_setup.hpp"
#include "core/segment/seg_opt.hpp"

namespace salient::core {

// The estimated times of `plan` and of the two uniform baselines (PlanTimes); nullopt without a
// time model.
std::optional<PlanTimes> plan_times(const PlanningSetup& setup, const LayerPlan& plan);

// "2 h 05 min", "48 min".
std::string duration_text(double seconds);
// One line: the plan's time; uniform at the finest layer with the saving; uniform at the
// default height, how much slower or quicker it is, and its RSMD against the plan's.
std::string times_text(const PlanTimes& times, double fine_layer_height, double plan_rsmd);

// `model`: the model's file name; `planner`: its name as given; `seconds`: time taken to plan.
PlanDocument plan_document(const PlanningSetup& setup, const std::string& model, const std::string& planner,
                           const PlanResult& result, const PlanTarget& target, double seconds);

// The times of a segmented plan, all on `timer` (the regions' toolpaths and G-code, as SegOpt
// decided by): the plan's (SegOpt's result), and the baselines of PlanTimes each as one whole
// region. The layer time model cannot time regions side by side.
PlanTimes segmented_plan_times(const PlanningSetup& setup, const SegOptResult& result,
                               const RegionTimer& timer);

// The printed layers are the regions' merged heights (printed_heights); E and RSMD those of all
// regions together (regions_error).
PlanDocument segmented_plan_document(const PlanningSetup& setup, const std::string& model,
                                     const std::string& planner, const SegOptResult& result, double seconds,
                                     std::optional<PlanTimes> times = std::nullopt);

// `whole`: the profile the regions' cells are on.
SegmentationReport segmentation_report(const SegOptResult& result, const ZProfile& whole);

}  // namespace salient::core
