// `salient plan MODEL`: choose layer thicknesses with one planner; print, save JSON and SVG.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "clients/cli/segment_report.hpp"
#include "core/common/input_error.hpp"
#include "core/export/plan_json.hpp"
#include "core/pipeline/plan_report.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/segment/regions_svg.hpp"
#include "core/slicing/plan_svg.hpp"

namespace salient::cli {
namespace {

struct PlanCommandOptions {
  core::Settings settings;  // as given on the command line
  SettingOptions given;
  core::PlanOptions plan;  // settings.slice.plan once applied
  bool json = false;
  std::string output, svg;
};

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw core::InputError(path, {}, "cannot write");
}

// plan --segment: SegOpt's regions, timed on the generic-i3 profile (plan has no printer).
int plan_segmented(const PlanCommandOptions& o, const core::PlanningSetup& setup,
                   const core::Planner& planner) {
  const auto printer = core::builtin_printer("generic-i3");
  const auto t0 = std::chrono::steady_clock::now();
  core::SegOptOptions options;
  options.depth = o.plan.segment_depth;
  options.planes = o.plan.segment_planes;
  // Timed as slice would print it (its toolpath settings for generic-i3).
  const core::RegionSliceSettings settings = core::region_slice_settings(o.settings.slice, *printer);
  const core::SegOptResult r = core::segment_model(setup, planner, settings, *printer, {}, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const core::ZProfile& p = *setup.profile;
  const std::string name = std::filesystem::path(o.plan.mesh.model).filename().string();
  const core::PlanDocument plan = core::segmented_plan_document(
      setup, name, std::string(core::to_string(o.plan.planner)), r, seconds,
      core::segmented_plan_times(setup, r, core::region_timer(setup, settings, *printer)));
  const std::string text = core::plan_json(plan);
  if (!o.output.empty()) write_file(o.output, text);
  const std::vector<double> heights = core::printed_heights(p, r.regions);
  if (!o.svg.empty())
    write_file(o.svg,
               core::regions_svg(p, r.regions,
                                 name + " — " + std::string(core::to_string(o.plan.planner)) + "+segopt, " +
                                     std::to_string(heights.size()) + " printed layers"));
  if (o.json) {
    std::fputs(text.c_str(), stdout);
    return 0;
  }
  std::printf("%s: %s planner with SegOpt, %s metric, %s\n", name.c_str(),
              std::string(core::to_string(o.plan.planner)).c_str(),
              std::string(core::to_string(o.plan.metric)).c_str(), core::saliency_text(o.plan).c_str());
  std::printf("  layers   %zu printed heights (fine %d)\n  time     %.3f s\n", heights.size(),
              core::finest_layer_count(p, setup.first_cells), seconds);
  if (plan.times)
    std::printf("  print    %s (estimated on the G-code)\n",
                core::times_text(*plan.times, p.params().min_layer, plan.rsmd).c_str());
  if (p.dropped_faces() > 0)
    std::printf("  warning  %zu faces of zero or non-finite area were left out of the profile\n",
                p.dropped_faces());
  print_segmentation(r, p);
  return 0;
}

}  // namespace

void add_plan_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<PlanCommandOptions>();
  CLI::App* cmd = app.add_subcommand("plan", "Choose layer thicknesses for a model");
  o->given = add_plan_options(*cmd, o->settings, o->json, core::for_plan);
  cmd->add_option("-o,--output", o->output, "Write the plan as JSON to this file");
  cmd->add_option("--svg", o->svg, "Write a plot of the plan (thickness and saliency against height)");
  cmd->callback([o, &action] {
    action = [o] {
      o->given.apply(o->settings);
      o->plan = o->settings.slice.plan;
      core::check_plan_options(o->plan);
      resolve_auto_up(o->plan.mesh, &o->plan, o->json);
      const auto planner = core::make_planner(o->plan.planner);
      if (o->plan.segment) {  // timed on generic-i3: placed on its bed
        o->plan.mesh.bed_center_x = core::builtin_printer("generic-i3")->bed_center_x();
        o->plan.mesh.bed_center_y = core::builtin_printer("generic-i3")->bed_center_y();
      }
      // plan has no printer: the first layer, the baseline height and the times are generic-i3's
      // (PlanOptions' defaults).
      const auto setup = core::prepare(o->plan);
      if (o->plan.segment) return plan_segmented(*o, *setup, *planner);
      const core::PlanTarget target = core::target_of(o->plan, *setup);
      const auto t0 = std::chrono::steady_clock::now();
      const core::PlanResult result = planner->plan(setup->request(target));
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const std::string name = std::filesystem::path(o->plan.mesh.model).filename().string();
      const std::string text = core::plan_json(core::plan_document(
          *setup, name, std::string(core::to_string(o->plan.planner)), result, target, seconds));
      if (!o->output.empty()) write_file(o->output, text);
      const core::ZProfile& p = *setup->profile;
      const auto times = core::plan_times(*setup, result.plan);
      if (!o->svg.empty())
        write_file(o->svg,
                   core::plan_svg(*setup->objective, result.plan,
                                  name + " — " + std::string(core::to_string(o->plan.planner)) + ", " +
                                      std::to_string(result.plan.layer_count()) + " layers",
                                  times ? "estimated " + core::times_text(*times, p.params().min_layer,
                                                                          setup->objective->rsmd(result.plan))
                                        : std::string()));
      if (o->json) {
        std::fputs(text.c_str(), stdout);
        return 0;
      }
      std::printf("%s: %s planner, %s metric, %s\n", name.c_str(),
                  std::string(core::to_string(o->plan.planner)).c_str(),
                  std::string(core::to_string(o->plan.metric)).c_str(), core::saliency_text(o->plan).c_str());
      // Counted as the fine and coarse planners plan them, with the fixed first layer.
      const int fine = core::finest_layer_count(p, setup->first_cells);
      std::printf("  layers   %d (fine %d, coarse %d): %.1f%% fewer than fine\n", result.plan.layer_count(),
                  fine, core::fewest_layer_count(p, setup->first_cells),
                  100.0 * (1 - double(result.plan.layer_count()) / fine));
      std::printf("  E        %.6g", setup->objective->error(result.plan));
      if (target.epsilon) std::printf(" (epsilon %.6g = %.3g x E(coarse))", *target.epsilon, setup->rho);
      std::printf("\n  RSMD     %.6g\n  time     %.3f s\n", setup->objective->rsmd(result.plan), seconds);
      if (times)
        std::printf(
            "  print    %s (estimated; objective %s)\n",
            core::times_text(*times, p.params().min_layer, setup->objective->rsmd(result.plan)).c_str(),
            std::string(core::to_string(setup->goal)).c_str());
      if (p.dropped_faces() > 0)
        std::printf("  warning  %zu faces of zero or non-finite area were left out of the profile\n",
                    p.dropped_faces());
      if (!result.note.empty()) std::printf("  note     %s\n", result.note.c_str());
      for (const core::PlanStep& s : result.trace)
        std::printf("  step     %-10s %4d layers  E %.6g\n", s.step.c_str(), s.layers, s.error);
      return 0;
    };
  });
}

}  // namespace salient::cli
