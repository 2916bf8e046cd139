// `salient compare MODEL`: the paper's Table 1 for one model, every planner side by side.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/slicing/comparison.hpp"

namespace salient::cli {
namespace {

// The rows exact+segopt and adapslice+segopt: SegOpt (paper §5) on top of each, at ρ, timed on
// generic-i3. Layers are the printed heights of the merged regions; RSMD is their summed loss over
// the whole model's E(coarse), comparable with the other rows.
void add_segopt_rows(const core::PlanningSetup& setup, core::Comparison& c) {
  const auto printer = core::builtin_printer("generic-i3");
  for (const char* name : {"exact", "adapslice"}) {
    const auto planner = core::make_planner(name);
    const auto t0 = std::chrono::steady_clock::now();
    const core::SegOptResult r = core::segment_model(setup, *planner, {}, *printer);
    core::ComparisonRow row;
    row.planner = std::string(name) + "+segopt";
    row.layers_at_rsmd = static_cast<int>(core::printed_heights(*setup.profile, r.regions).size());
    const double e_coarse = setup.objective->e_coarse();
    row.rsmd_at_rsmd = e_coarse > 0 ? core::regions_error(r.regions) / e_coarse : 0;
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    char minutes[96];
    std::snprintf(minutes, sizeof minutes, "; print %.1f min vs %.1f min unsegmented (generic-i3)",
                  r.seconds / 60, r.whole_seconds / 60);
    row.note = r.note + minutes;
    c.rows.push_back(std::move(row));
  }
}

}  // namespace

void add_compare_command(CLI::App& app, CommandAction& action) {
  struct CompareOptions {
    core::Settings settings;  // as given on the command line
    SettingOptions given;
    core::PlanOptions plan;  // settings.slice.plan once applied
    bool json = false;
  };
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Compare every planner on one model (the paper's Table 1)");
  o->given = add_plan_options(*cmd, o->settings, o->json, core::for_compare);
  cmd->callback([o, &action] {
    action = [o] {
      o->given.apply(o->settings);
      o->plan = o->settings.slice.plan;
      resolve_auto_up(o->plan.mesh, &o->plan, o->json);
      const auto printer = core::builtin_printer("generic-i3");  // the segopt rows are timed on it
      o->plan.mesh.bed_center_x = printer->bed_center_x();
      o->plan.mesh.bed_center_y = printer->bed_center_y();
      const auto setup = core::prepare(o->plan);
      core::PlanRequest base = setup->request({});
      base.goal = core::PlanGoal::layers;  // Table 1 compares layer counts: exact as the fewest layers
      core::Comparison c = core::compare_planners(base, setup->rho, core::planner_names());
      add_segopt_rows(*setup, c);
      const std::string name = std::filesystem::path(o->plan.mesh.model).filename().string();
      if (o->json) {
        nlohmann::json rows = nlohmann::json::array();
        for (const auto& r : c.rows)
          rows.push_back({{"planner", r.planner},
                          {"layers_at_count", r.layers_at_count},
                          {"rsmd_at_count", r.rsmd_at_count},
                          {"layers_at_rsmd", r.layers_at_rsmd},
                          {"rsmd_at_rsmd", r.rsmd_at_rsmd},
                          {"seconds", r.seconds},
                          {"note", r.note}});
        nlohmann::json trace = nlohmann::json::array();
        for (const auto& s : c.adapslice_trace)
          trace.push_back({{"step", s.step}, {"layers", s.layers}, {"E", s.error}});
        const nlohmann::json j = {{"model", name},
                                  {"metric", std::string(core::to_string(o->plan.metric))},
                                  {"saliency", std::string(core::to_string(o->plan.saliency))},
                                  {"rho", c.rho},
                                  {"epsilon", c.epsilon},
                                  {"reference_layers", c.reference_layers},
                                  {"reference_rsmd", c.reference_rsmd},
                                  {"fine_layers", c.fine_layers},
                                  {"coarse_layers", c.coarse_layers},
                                  {"rows", rows},
                                  {"adapslice_trace", trace}};
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
      }
      std::printf(
          "%s: %s metric, %s saliency, rho %.3g; exact needs %d layers (fine %d, coarse %d), RSMD %.4f\n",
          name.c_str(), std::string(core::to_string(o->plan.metric)).c_str(),
          std::string(core::to_string(o->plan.saliency)).c_str(), c.rho, c.reference_layers, c.fine_layers,
          c.coarse_layers, c.reference_rsmd);
      std::printf("%-16s %14s %16s %9s  %s\n", "planner", "RSMD @ layers", "layers @ RSMD", "seconds",
                  "note");
      for (const auto& r : c.rows) {
        if (r.layers_at_count > 0)
          std::printf("%-16s %8.4f @%4d %9d (%.4f) %9.3f  %s\n", r.planner.c_str(), r.rsmd_at_count,
                      r.layers_at_count, r.layers_at_rsmd, r.rsmd_at_rsmd, r.seconds, r.note.c_str());
        else  // the segopt rows: at ρ only
          std::printf("%-16s %14s %9d (%.4f) %9.3f  %s\n", r.planner.c_str(), "-", r.layers_at_rsmd,
                      r.rsmd_at_rsmd, r.seconds, r.note.c_str());
      }
      std::printf("adapslice trace:");
      for (const auto& s : c.adapslice_trace)
        std::printf(" %s %d (E %.4g);", s.step.c_str(), s.layers, s.error);
      std::printf("\n");
      return 0;
    };
  });
}

}  // namespace salient::cli
