#include "core/pipeline/slice_pipeline.hpp"

#include <algorithm>
#include <filesystem>

#include "core/common/input_error.hpp"
#include "core/export/three_mf.hpp"
#include "core/gcode/gcode_writer.hpp"
#include "core/mesh/ply_writer.hpp"
#include "core/pipeline/auto_orient.hpp"
#include "core/render/saliency_preview.hpp"
#include "core/slicing/plan_svg.hpp"

namespace salient::core {

SliceResult slice_model(SliceSettings s, const PrinterProfile& printer, const RunContext& run) {
  std::optional<OrientationReport> orientation;
  if (s.plan.mesh.up == "auto") {
    orientation = choose_orientation(s, printer, run);
    s.plan.mesh.up = orientation->up;
    if (orientation->scale) s.plan.mesh.height.reset(), s.plan.mesh.scale = *orientation->scale;
  }
  PlanOptions& plan = s.plan;
  if (s.min_layer_from_printer) plan.min_layer = printer.min_layer;
  if (s.max_layer_from_printer) plan.max_layer = printer.max_layer;
  if (!(s.toolpaths.line_width > 0)) throw InputError("--line-width", {}, "must be positive");
  plan.mesh.bed_center_x = printer.bed_center_x();
  plan.mesh.bed_center_y = printer.bed_center_y();
  const auto planner = make_planner(plan.planner);
  if (!planner) throw InputError("--planner", {}, "unknown planner '" + plan.planner + "'");

  const auto setup = prepare(plan, run);
  run.check();
  run.report("plan", 0);
  PlanRequest request = setup->request(target_of(plan, *setup));
  request.run = run;
  const PlanResult planned = planner->plan(request);
  run.check();

  SliceResult out;
  out.orientation = std::move(orientation);
  std::vector<double> boundaries;  // the bed, then each layer's top
  for (int b : planned.plan.boundaries) boundaries.push_back(setup->profile->z(b));
  out.z.assign(boundaries.begin() + (boundaries.empty() ? 0 : 1), boundaries.end());
  if (s.combine_infill) s.toolpaths.combine_infill_up_to = printer.max_layer;
  auto toolpaths = generate_toolpaths(setup->model.loaded.mesh, boundaries, s.toolpaths, run);
  if (s.support) {
    s.support_settings.line_width = s.toolpaths.line_width;
    add_support(toolpaths, s.support_settings, run);
  }
  run.check();
  run.report("gcode", 0);
  const ZProfile& p = *setup->profile;
  out.model_name = std::filesystem::path(plan.mesh.model).filename().string();
  out.layers = planned.plan.layer_count();
  out.finest_layers = p.most_layers();
  out.error = setup->objective->error(planned.plan);
  out.rsmd = setup->objective->rsmd(planned.plan);
  GcodeSettings gs;
  gs.summary = {"model = " + out.model_name,
                "planner = " + plan.planner + ", metric " + plan.metric + ", saliency " + plan.saliency,
                "plan = " + std::to_string(out.layers) + " layers (finest " + std::to_string(out.finest_layers) + "), E " +
                    std::to_string(out.error) + ", RSMD " + std::to_string(out.rsmd)};
  GcodeResult g = write_gcode(toolpaths, printer, gs);
  out.gcode = std::move(g.text);
  out.print_seconds = g.seconds;
  out.filament_mm = g.filament_mm;
  for (const auto& l : toolpaths) out.open_contours += l.open_chains;
  if (s.artefacts) {
    const Mesh& mesh = setup->model.loaded.mesh;
    out.plot_svg = plan_svg(*setup->objective, planned.plan, out.model_name + " — " + plan.planner + ", " + plan.metric);
    out.model_3mf = three_mf(mesh, boundaries, out.model_name);
    std::vector<Color> colors(setup->saliency.size());
    std::transform(setup->saliency.begin(), setup->saliency.end(), colors.begin(), heat_color);
    out.saliency_ply = ply_bytes(mesh, setup->saliency, colors);
  }
  run.report("gcode", 1);
  return out;
}

}  // namespace salient::core
