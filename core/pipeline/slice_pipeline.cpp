#include "core/pipeline/slice_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
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

// Without support, the printed layers must stand on the bed, each on the one below: where an
// open mesh's sections are left out (holes wider than max_gap, an open bottom), the layers above
// would be printed in mid-air. Throws InputError saying where the gap is.
void check_layers_stand(const std::vector<LayerToolpaths>& layers, const std::string& model_name,
                        std::size_t open_contours) {
  const auto empty = [&](std::size_t i) { return layers[i].region.empty(); };
  std::size_t first = 0;
  while (first < layers.size() && empty(first)) ++first;
  if (first == layers.size() && open_contours == 0) {
    throw InputError(model_name, {},
                     "no layer has an outline with any area: nothing would print. The model is a surface "
                     "without thickness (a sheet, not a solid); give it a thickness in a modelling tool");
  }
  if (first == layers.size()) {
    throw InputError(model_name, {},
                     "no layer has a closed outline: nothing would print (" + std::to_string(open_contours) +
                         " open contours were left out: the mesh is open). Close its holes in a mesh "
                         "repair tool first");
  }
  // [from, to): layers with nothing under a printed one.
  std::size_t from = 0, to = first;
  for (std::size_t i = first + 1; i < layers.size() && to == 0;) {
    std::size_t j = i;
    while (j < layers.size() && empty(j)) ++j;
    if (j > i && j < layers.size()) from = i, to = j;
    i = j + 1;
  }
  if (to == 0) return;
  std::size_t open_there = 0;
  for (std::size_t i = from; i < to; ++i) open_there += layers[i].open_chains;
  std::ostringstream where;
  where.precision(3);
  where << "nothing would print from " << layers[from].z_bottom << " to " << layers[to].z_bottom
        << " mm, so the layers above would start in mid-air, not on the bed or a layer below";
  if (open_there == 0)
    throw InputError(model_name, {},
                     where.str() +
                         " (a part floats above the rest: nothing joins it to what is below). "
                         "Turn on {support}, or join or lower it in a modelling tool");
  throw InputError(model_name, {},
                   where.str() + " (" + std::to_string(open_there) +
                       " open contours were left out there: the mesh has holes, e.g. an open bottom, that "
                       "repair could not close). Close them in a mesh repair tool, or turn on {support}");
}

// Layers whose sections were only open chains, filled from the layers around them: printable,
// but their outline is a guess the owner should see in the preview.
std::optional<SliceWarning> filled_layers_warning(const std::vector<LayerToolpaths>& layers) {
  std::size_t count = 0;
  const LayerToolpaths *first = nullptr, *last = nullptr;
  for (const LayerToolpaths& l : layers) {
    if (!l.filled) continue;
    ++count;
    if (!first) first = &l;
    last = &l;
  }
  if (count == 0) return std::nullopt;
  std::ostringstream text;
  text.precision(3);
  text << count << (count == 1 ? " layer" : " layers") << " between " << first->z_bottom << " and "
       << last->z_top
       << " mm had only open contours (tears in the mesh) and took the outline of the layers around them: "
          "check them in the preview, or repair the mesh";
  return SliceWarning{"layers_filled", text.str()};
}

std::vector<SliceWarning> left_out_warnings(const SliceResult& r, double max_gap) {
  std::vector<SliceWarning> out;
  if (r.dropped_faces > 0)
    out.push_back(
        {"faces_left_out", std::to_string(r.dropped_faces) +
                               " faces of zero or non-finite area were left out of the layer profile"});
  if (r.open_contours > 0)
    out.push_back({"open_contours", std::to_string(r.open_contours) +
                                        " open contours were left out (the mesh has holes wider than " +
                                        mm(max_gap) + ")"});
  if (r.stream.starves())
    out.push_back(
        {"stream_starves",
         "the G-code needs up to " + std::to_string(std::lround(r.stream.peak_commands_per_second)) +
             " commands per second, more than a " + std::to_string(r.stream.baud) + "-baud link carries (" +
             std::to_string(std::lround(r.stream.link_commands_per_second)) +
             "): it would stutter over USB serial (try the profile's gcode.arc_fitting or a "
             "coarser gcode.resolution)"});
  return out;
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
  plan.build_volume = BuildVolume{printer.bed_width, printer.bed_depth, printer.max_height};
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
  out.warnings = model_size_warnings(setup->model.placement.bounds, printer, out.model_name);
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
  for (const auto& l : toolpaths) out.open_contours += l.open_chains;
  if (!s.support) check_layers_stand(toolpaths, out.model_name, out.open_contours);
  const std::optional<SliceWarning> filled = filled_layers_warning(toolpaths);
  run.report("gcode", 0);
  out.layers = static_cast<int>(out.z.size());
  out.finest_layers = finest_layer_count(p, setup->first_cells);
  GcodeSettings gs;
  gs.cancel = run.cancel;
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
  // One print time everywhere: the G-code's estimate. The uniform prints beside it are the time
  // model's, scaled by this plan's estimate over its model time (the model is off the estimator
  // by much the same per cent for the three plans; support and travel count alike), so that
  // "print", the job's print_seconds and times.plan_s are one figure and the savings keep their
  // ratios. A segmented plan's times are the G-code's already.
  if (out.plan.times && !out.segmentation && out.plan.times->plan_seconds > 0 && g.seconds > 0)
    out.plan.times->scale(g.seconds / out.plan.times->plan_seconds);
  out.filament_mm = g.filament_mm;
  out.stream = g.stream;
  const std::vector<SliceWarning> left_out = left_out_warnings(out, s.toolpaths.max_gap);
  out.warnings.insert(out.warnings.end(), left_out.begin(), left_out.end());
  if (filled) out.warnings.push_back(*filled);
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
