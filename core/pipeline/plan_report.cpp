#include "core/pipeline/plan_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "core/pipeline/segmented_slicing.hpp"

namespace salient::core {
namespace {

// What every plan of this setup says: the model, the planner, the grid and its limits.
PlanDocument common(const PlanningSetup& setup, const std::string& model, const std::string& planner,
                    double seconds) {
  const ZProfile& p = *setup.profile;
  PlanDocument d;
  d.model = model;
  d.planner = planner;
  d.metric = std::string(metric_name(setup.objective->metric()));
  d.saliency_method = setup.saliency_text;
  d.height = p.height();
  d.grid = p.grid();
  d.min_layer = p.params().min_layer;
  d.max_layer = p.params().max_layer;
  d.fine_layers = finest_layer_count(p, setup.first_cells);
  d.coarse_layers = fewest_layer_count(p, setup.first_cells);
  d.seconds = seconds;
  return d;
}

}  // namespace

namespace {

// PlanTimes' layer counts and RSMD, and its times by `seconds` (of one plan of the whole model).
PlanTimes times_of(const PlanningSetup& setup, double plan_seconds,
                   const std::function<double(const LayerPlan&)>& seconds) {
  const ZProfile& p = *setup.profile;
  PlanTimes t;
  t.plan_seconds = plan_seconds;
  const LayerPlan fine = make_planner(PlannerKind::fine)->plan(setup.request(PlanTarget::within(0))).plan;
  t.fine_layers = fine.layer_count();
  t.fine_seconds = seconds(fine);
  t.default_layer_height = setup.default_layer;
  if (setup.default_layer > 0) {
    const double first = setup.first_cells > 0 ? p.z(setup.first_cells) : 0;
    const int n = (first > 0 ? 1 : 0) +
                  std::max(1, static_cast<int>(std::lround((p.height() - first) / setup.default_layer)));
    const LayerPlan uniform =
        make_planner(PlannerKind::uniform)->plan(setup.request(PlanTarget::count(n))).plan;
    t.default_layers = uniform.layer_count();
    t.default_seconds = seconds(uniform);
    t.default_rsmd = setup.objective->rsmd(uniform);
  }
  return t;
}

}  // namespace

std::optional<PlanTimes> plan_times(const PlanningSetup& setup, const LayerPlan& plan) {
  if (!setup.time) return std::nullopt;
  const LayerTimeModel& time = *setup.time;
  return times_of(setup, time.seconds(plan), [&](const LayerPlan& l) { return time.seconds(l); });
}

PlanTimes segmented_plan_times(const PlanningSetup& setup, const SegOptResult& result,
                               const RegionTimer& timer) {
  return times_of(setup, result.seconds, [&](const LayerPlan& plan) {
    PlanRegion whole;
    whole.last_cell = setup.profile->cells();
    whole.plan = plan;
    return timer({whole});
  });
}

std::string duration_text(double seconds) {
  const long minutes = std::lround(seconds / 60);
  char buf[48];
  if (minutes < 60)
    std::snprintf(buf, sizeof buf, "%ld min", minutes);
  else
    std::snprintf(buf, sizeof buf, "%ld h %02ld min", minutes / 60, minutes % 60);
  return buf;
}

std::string times_text(const PlanTimes& t, double fine_layer_height, double plan_rsmd) {
  const double vs_default = t.saving_vs_default();
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%s; uniform %g mm %s (%s, %.1f %% saved); uniform %g mm %s (%s %s, RSMD %.3f against %.3f)",
                duration_text(t.plan_seconds).c_str(), fine_layer_height,
                duration_text(t.fine_seconds).c_str(), duration_text(t.saving_vs_fine()).c_str(),
                t.saving_vs_fine_percent(), t.default_layer_height, duration_text(t.default_seconds).c_str(),
                duration_text(std::fabs(vs_default)).c_str(), vs_default >= 0 ? "slower" : "quicker",
                t.default_rsmd, plan_rsmd);
  return buf;
}

PlanDocument plan_document(const PlanningSetup& setup, const std::string& model, const std::string& planner,
                           const PlanResult& result, const PlanTarget& target, double seconds) {
  const Objective& obj = *setup.objective;
  PlanDocument d = common(setup, model, planner, seconds);
  for (const LayerReport& l : obj.layers(result.plan))
    d.layers.push_back({l.z_bottom, l.z_top, l.height, l.saliency, l.cos, l.sm});
  d.error = obj.error(result.plan);
  d.rsmd = obj.rsmd(result.plan);
  d.epsilon = target.epsilon;
  if (target.epsilon) d.rho = setup.rho;
  if (target.layers) d.requested_layers = *target.layers;
  d.note = result.note;
  for (const PlanStep& s : result.trace) d.trace.push_back({s.step, s.layers, s.error});
  d.objective = std::string(to_string(setup.goal));
  d.times = plan_times(setup, result.plan);
  return d;
}

PlanDocument segmented_plan_document(const PlanningSetup& setup, const std::string& model,
                                     const std::string& planner, const SegOptResult& result, double seconds,
                                     std::optional<PlanTimes> times) {
  const ZProfile& p = *setup.profile;
  PlanDocument d = common(setup, model, planner, seconds);
  double below = 0;
  for (double top : printed_heights(p, result.regions)) {
    d.layers.push_back({below, top, top - below, std::nullopt, std::nullopt, std::nullopt});
    below = top;
  }
  double e_coarse = 0;
  for (const PlanRegion& r : result.regions) e_coarse += setup.rho > 0 ? r.epsilon / setup.rho : 0;
  d.error = regions_error(result.regions);
  d.rsmd = e_coarse > 0 ? d.error / e_coarse : 0;
  d.rho = setup.rho;
  d.note = result.note;
  d.segmentation = segmentation_report(result, p);
  d.times = std::move(times);
  return d;
}

SegmentationReport segmentation_report(const SegOptResult& r, const ZProfile& whole) {
  SegmentationReport out;
  out.cut = r.cut;
  out.note = r.note;
  out.whole_seconds = r.whole_seconds;
  out.parts_seconds = r.parts_seconds;
  out.seconds = r.seconds;
  for (const PlanRegion& region : r.regions) {
    SegmentationReport::Region g;
    g.side = region.side;
    g.sub = region.sub;
    g.z_bottom = whole.z(region.first_cell);
    g.z_top = whole.z(region.last_cell);
    g.layers = region.layers();
    g.error = region.error;
    g.epsilon = region.epsilon;
    for (int b : region.plan.boundaries) g.boundaries.push_back(whole.z(b));
    for (const Point2& p : region.clip) g.clip.push_back({p.x, p.y});
    out.regions.push_back(std::move(g));
  }
  for (const Slab& s : r.slabs)
    out.slabs.push_back({whole.z(s.first_cell), whole.z(s.last_cell), s.merged, {s.loss[0], s.loss[1]}});
  if (r.seam)
    out.plane =
        SegmentationReport::Plane{r.seam->plane.nx,  r.seam->plane.ny,   r.seam->plane.offset, r.seam->cost,
                                  r.seam->seam_mean, r.seam->difference, r.seam->length,       r.seam->share};
  return out;
}

}  // namespace salient::core
