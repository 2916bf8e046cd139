#include "core/pipeline/slice_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/common/input_error.hpp"
#include "core/export/three_mf.hpp"
#include "core/gcode/gcode_writer.hpp"
#include "core/mesh/ply_writer.hpp"
#include "core/pipeline/auto_orient.hpp"
#include "core/pipeline/plan_report.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/render/model_thumbnail.hpp"
#include "core/render/saliency_preview.hpp"
#include "core/segment/regions_svg.hpp"
#include "core/slicing/plan_svg.hpp"

namespace salient::core {
namespace {

std::string mm(double v) {
  std::ostringstream s;
  s << v << " mm";
  return s.str();
}

}  // namespace

void check_slice_settings(const SliceSettings& s, const PrinterProfile& printer) {
  PlanOptions plan = s.plan;
  if (s.min_layer_from_printer) plan.min_layer = printer.min_layer;
  if (s.max_layer_from_printer) plan.max_layer = printer.max_layer;
  if (!(s.toolpaths.line_width > 0)) throw InputError(SettingId::line_width, "must be positive");
  check_plan_options(plan);
  // The profile's thickest layer is what its nozzle prints; a thicker one asked for would be
  // planned and printed without a word.
  if (plan.max_layer > printer.max_layer + 1e-9)
    throw InputError(SettingId::max_layer, mm(plan.max_layer) + " is above the thickest layer " + printer.id +
                                               " prints: its profile's layers.max is " +
                                               mm(printer.max_layer) + " (" + mm(printer.nozzle_diameter) +
                                               " nozzle)");
}

RegionSliceSettings region_slice_settings(const SliceSettings& s, const PrinterProfile& printer) {
  RegionSliceSettings out{s.toolpaths, s.support, s.support_settings};
  out.toolpaths.solid_infill_below_area = printer.solid_infill_below_area;
  out.toolpaths.resolution = printer.gcode_resolution;
  if (s.combine_infill) out.toolpaths.combine_infill_up_to = printer.max_layer;
  return out;
}

TimeModelParams time_model_params(const PrinterProfile& printer, const ToolpathSettings& toolpaths,
                                  const GcodeSettings& gcode) {
  TimeModelParams t;
  t.print_speed = printer.print_speed;
  t.first_layer_speed = printer.first_layer_speed;
  t.travel_speed = printer.travel_speed;
  t.line_width = toolpaths.line_width;
  t.walls = toolpaths.walls;
  t.infill_density = toolpaths.infill_density;
  t.top_thickness = toolpaths.top_thickness;
  t.bottom_thickness = toolpaths.bottom_thickness;
  t.combine_infill_up_to = toolpaths.combine_infill_up_to;
  t.min_layer_time = gcode.min_layer_time;
  t.min_print_speed = gcode.min_print_speed;
  return t;
}

namespace {

// The time objective decides on the layer time model, which is some per cent off the estimator
// on the G-code (BENCHMARKS.md "The layer time model against the estimator") — more, on some
// models, than the model's margin between its plan and the fewest layers'. So exact plans both
// (the second plan is `--objective layers`' own), each is timed as it prints (toolpaths and
// G-code, the estimator the user sees) and the quicker kept: `--objective time` never takes
// longer than `--objective layers`. Both meet the same ε, so the choice costs no quality; it
// costs one more plan and two more toolpath passes, which are cheap beside saliency.
void keep_quicker_on_gcode(const PlanningSetup& setup, const Planner& planner, const PlanRequest& request,
                           const RegionSliceSettings& settings, const PrinterProfile& printer,
                           PlanResult& planned, const RunContext& run) {
  PlanRequest by_layers = request;
  by_layers.goal = PlanGoal::layers;
  PlanResult fewest = planner.plan(by_layers);
  if (fewest.plan.boundaries == planned.plan.boundaries) return;
  const RunContext quiet{run.cancel, {}};  // their toolpath progress is not the job's
  const auto seconds = [&](const LayerPlan& plan) {
    PlanRegion whole;
    whole.last_cell = setup.profile->cells();
    whole.plan = plan;
    return region_print_seconds(setup.model.loaded.mesh, *setup.profile, {whole}, settings, printer, quiet);
  };
  // A second's margin: the file's estimate adds the start and end code, whose junctions with the
  // layers move fractions of a second.
  const double t = seconds(planned.plan), l = seconds(fewest.plan);
  if (t < l - 1) return;
  planned.plan = std::move(fewest.plan);
  planned.note = "time objective: the fewest layers' plan prints as fast on the G-code (" +
                 std::to_string(std::lround(l)) + " s against " + std::to_string(std::lround(t)) +
                 " s), so it is kept";
}

}  // namespace

SliceResult slice_model(SliceSettings s, const PrinterProfile& printer, const RunContext& run) {
  check_slice_settings(s, printer);  // before the orientations are sliced
  const RegionSliceSettings region_settings = region_slice_settings(s, printer);
  s.toolpaths = region_settings.toolpaths;
  std::optional<OrientationReport> orientation;
  if (s.plan.mesh.up == "auto") {
    orientation = choose_orientation(s, printer, run);
    s.plan.mesh.up = orientation->up;
    if (orientation->scale) s.plan.mesh.height.reset(), s.plan.mesh.scale = *orientation->scale;
  }
  PlanOptions& plan = s.plan;
  if (s.min_layer_from_printer) plan.min_layer = printer.min_layer;
  if (s.max_layer_from_printer) plan.max_layer = printer.max_layer;
  plan.mesh.bed_center_x = printer.bed_center_x();
  plan.mesh.bed_center_y = printer.bed_center_y();
  plan.first_layer = printer.first_layer_height;
  plan.default_layer = printer.default_layer_height;
  plan.time_model = time_model_params(printer, s.toolpaths, GcodeSettings{});
  const auto planner = make_planner(plan.planner);
  const auto setup = prepare(plan, run);
  run.check();
  const ZProfile& p = *setup->profile;
  std::vector<PlanRegion> regions;
  SliceResult out;
  out.orientation = std::move(orientation);
  out.dropped_faces = p.dropped_faces();
  out.model_name = std::filesystem::path(plan.mesh.model).filename().string();
  const auto t0 = std::chrono::steady_clock::now();
  const auto planning_seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (plan.segment) {
    SegOptOptions options;
    options.depth = plan.segment_depth;
    options.planes = plan.segment_planes;
    out.segmentation = segment_model(*setup, *planner, region_settings, printer, run, options);
    regions = out.segmentation->regions;
    double e_coarse = 0;
    for (const PlanRegion& r : regions) e_coarse += setup->rho > 0 ? r.epsilon / setup->rho : 0;
    out.error = regions_error(regions);
    out.rsmd = e_coarse > 0 ? out.error / e_coarse : 0;
    const double planned_in = planning_seconds();
    out.plan = segmented_plan_document(
        *setup, out.model_name, std::string(to_string(plan.planner)), *out.segmentation, planned_in,
        segmented_plan_times(*setup, *out.segmentation, region_timer(*setup, region_settings, printer, run)));
  } else {
    run.report("plan", 0);
    const PlanTarget target = target_of(plan, *setup);
    PlanRequest request = setup->request(target);
    request.run = run;
    PlanResult planned = planner->plan(request);
    if (request.goal == PlanGoal::time && plan.planner == PlannerKind::exact && !target.layers)
      keep_quicker_on_gcode(*setup, *planner, request, region_settings, printer, planned, run);
    out.plan = plan_document(*setup, out.model_name, std::string(to_string(plan.planner)), planned, target,
                             planning_seconds());
    PlanRegion whole;
    whole.last_cell = p.cells();
    whole.plan = planned.plan;
    out.error = setup->objective->error(whole.plan);
    out.rsmd = setup->objective->rsmd(whole.plan);
    regions = {std::move(whole)};
  }
  run.check();
  out.z = printed_heights(p, regions);
  std::vector<double> boundaries{0};  // the bed, then each printed layer's top
  boundaries.insert(boundaries.end(), out.z.begin(), out.z.end());
  auto toolpaths = region_toolpaths(setup->model.loaded.mesh, p, regions, region_settings, run);
  run.check();
  run.report("gcode", 0);
  out.layers = static_cast<int>(out.z.size());
  out.finest_layers = p.most_layers();
  GcodeSettings gs;
  gs.summary = {"model = " + out.model_name,
                "planner = " + std::string(to_string(plan.planner)) + ", metric " +
                    std::string(to_string(plan.metric)) + ", " + saliency_text(plan),
                "plan = " + std::to_string(out.layers) + " layers (finest " +
                    std::to_string(out.finest_layers) + "), E " + std::to_string(out.error) + ", RSMD " +
                    std::to_string(out.rsmd)};
  if (out.segmentation) gs.summary.push_back("segmentation = " + out.segmentation->note);
  // The model as placed on the bed, so the thumbnail shows it standing as it prints.
  for (const ThumbnailSize& size : printer.thumbnails)
    gs.thumbnails.push_back({size.width, size.height,
                             png_bytes(render_thumbnail(setup->model.loaded.mesh, size.width, size.height))});
  GcodeResult g = write_gcode(toolpaths, printer, gs);
  out.gcode = std::move(g.text);
  out.print_seconds = g.seconds;
  out.filament_mm = g.filament_mm;
  out.stream = g.stream;
  for (const auto& l : toolpaths) out.open_contours += l.open_chains;
  if (s.artefacts) {
    const Mesh& mesh = setup->model.loaded.mesh;
    const std::string title = out.model_name + " — " + std::string(to_string(plan.planner)) + ", " +
                              std::string(to_string(plan.metric));
    const std::string caption =
        out.plan.times ? "estimated " + times_text(*out.plan.times, p.params().min_layer, out.rsmd)
                       : std::string();
    out.plot_svg = regions.size() == 1 ? plan_svg(*setup->objective, regions[0].plan, title, caption)
                                       : regions_svg(p, regions, title);
    out.model_3mf = three_mf(mesh, boundaries, out.model_name);
    std::vector<Color> colors(setup->saliency.size());
    std::transform(setup->saliency.begin(), setup->saliency.end(), colors.begin(), heat_color);
    out.saliency_ply = ply_bytes(mesh, setup->saliency, colors);
  }
  run.report("gcode", 1);
  return out;
}

}  // namespace salient::core
