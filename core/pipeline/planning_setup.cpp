#include "core/pipeline/planning_setup.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/common/input_error.hpp"
#include "core/pipeline/slice_warning.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::core {

PlanRequest PlanningSetup::request(PlanTarget target) const {
  return PlanRequest{*objective, &model.loaded.mesh, geometric.get(), target, seed, {},
                     goal,       time.get(),         first_cells};
}

void check_plan_options(const PlanOptions& o) {
  if (o.segment && (o.layers || o.layer_height))
    throw InputError(SettingId::segment, "works to a quality target ({rho}), not to a layer count");
  if (o.segment && o.planner == PlannerKind::ha13)
    throw InputError(SettingId::planner,
                     "ha13 cuts the whole model's sections, so it cannot plan the parts of {segment}");
  if (o.rho) validate_rho(*o.rho);
  if (o.layers && *o.layers <= 0) throw InputError(SettingId::layers, "must be a positive number of layers");
  if (o.layer_height && !(*o.layer_height > 0)) throw InputError(SettingId::layer_height, "must be positive");
  if (o.layer_height && o.planner != PlannerKind::uniform)
    throw InputError(SettingId::layer_height,
                     "applies to {planner} uniform; use {layers} for " + std::string(to_string(o.planner)));
  validate(SlicingParams{o.min_layer, o.max_layer, o.grid});
}

std::unique_ptr<PlanningSetup> prepare(const PlanOptions& o, const RunContext& run) {
  check_plan_options(o);  // before loading: a bad option should not wait for a big model
  const SlicingParams params{o.min_layer, o.max_layer, o.grid};
  const Metric metric = o.metric;
  const SaliencyMethod method = saliency_method(o);

  auto s = std::make_unique<PlanningSetup>();
  run.report("load", 0);
  s->model = load_placed(o.mesh, o.saliency_file);
  // Before saliency: the placed model's size decides the work every later phase does.
  check_work_bounds(s->model.placement.bounds, o.mesh, o.min_layer, o.grid, o.build_volume);
  run.check();
  const std::string name = std::filesystem::path(o.mesh.model).filename().string();
  check_printable_height(s->model.placement.bounds, o.first_layer, name);  // before the saliency
  run.report("saliency", 0);
  // On the file's own surface: a cap over a hole is not what a viewer looks at, and a cap over a
  // flat sheet would give the remesher a zero-thickness solid.
  const Mesh surface = file_surface(s->model.loaded);
  s->saliency = o.saliency_cache ? o.saliency_cache->get(surface, method, name, run)
                                 : compute_saliency(surface, method, name, run);
  run.check();
  s->profile = std::make_unique<ZProfile>(ZProfile::build(s->model.loaded.mesh, s->saliency, params, run));
  s->objective = std::make_unique<Objective>(*s->profile, metric, false);
  s->geometric = std::make_unique<Objective>(*s->profile, metric, true);
  s->time = std::make_unique<LayerTimeModel>(s->model.loaded.mesh, *s->profile, o.time_model);
  s->goal = o.objective;
  if (o.first_layer > 0)
    s->first_cells = std::clamp(static_cast<int>(std::lround(o.first_layer / o.grid)),
                                s->profile->min_cells(), s->profile->max_cells());
  s->default_layer = o.default_layer;
  s->rho = o.rho.value_or(0.05);
  s->seed = o.seed;
  s->saliency_text = saliency_text(o);
  return s;
}

SaliencyMethod saliency_method(const PlanOptions& o) {
  return o.saliency_file.empty() ? o.saliency : SaliencyMethod::painted;
}

std::string saliency_text(const PlanOptions& o) {
  const std::string method(to_string(saliency_method(o)));
  if (o.saliency_file.empty()) return method + " saliency";
  return method + " saliency from " + std::filesystem::path(o.saliency_file).filename().string();
}

PlanTarget target_of(const PlanOptions& o, const PlanningSetup& s) {
  if (o.layers) return PlanTarget::count(*o.layers);
  if (o.layer_height) {
    // Above a fixed first layer, the rest at the height asked for.
    const double first = s.first_cells > 0 ? s.profile->z(s.first_cells) : 0;
    return PlanTarget::count(
        (first > 0 ? 1 : 0) +
        std::max(1, static_cast<int>(std::lround((s.profile->height() - first) / *o.layer_height))));
  }
  return PlanTarget::within(s.objective->epsilon(s.rho));
}

}  // namespace salient::core
