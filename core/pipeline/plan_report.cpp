#include "core/pipeline/plan_report.hpp"

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
  d.height = p.height();
  d.grid = p.grid();
  d.min_layer = p.params().min_layer;
  d.max_layer = p.params().max_layer;
  d.fine_layers = p.most_layers();
  d.coarse_layers = p.fewest_layers();
  d.seconds = seconds;
  return d;
}

}  // namespace

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
  return d;
}

PlanDocument segmented_plan_document(const PlanningSetup& setup, const std::string& model,
                                     const std::string& planner, const SegOptResult& result, double seconds) {
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
