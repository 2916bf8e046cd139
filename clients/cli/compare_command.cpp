// `salient compare MODEL`: the paper's Table 1 for one model, every planner side by side;
// `--plan FILE` scores a plan made elsewhere in the same table, `--peers` adds Cura's adaptive
// layers as a row.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "clients/cli/cura_peer.hpp"
#include "core/common/input_error.hpp"
#include "core/export/plan_file.hpp"
#include "core/pipeline/segmented_slicing.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/printer/printer_profile.hpp"
#include "core/slicing/comparison.hpp"
#include "core/slicing/given_plan.hpp"

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
    const core::SegOptResult r =
        core::segment_model(setup, *planner, core::region_slice_settings({}, *printer), *printer);
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

// A plan from elsewhere, on our grid, with what the user should know about how it was read.
struct ScoredFile {
  core::GivenPlan given;
  std::string format;
};

ScoredFile score_file(const core::PlanFile& file, const core::ZProfile& profile, const std::string& name) {
  return {core::given_plan(profile, file.tops, file.lines, name), file.format};
}

std::string limits_note(const core::GivenPlan& g) {
  return g.outside_limits > 0 ? std::to_string(g.outside_limits) + " layers outside min/max layer" : "";
}

// The row "cura": Cura's adaptive layers at their own count, with exact at that count and the
// layers exact needs for Cura's loss in the note.
void add_cura_row(const core::PlanningSetup& setup, const core::PlanRequest& base, core::Comparison& c) {
  const auto printer = core::builtin_printer("generic-i3");
  CuraSettings cs;
  cs.min_layer = setup.profile->min_cells() * setup.profile->grid();
  cs.max_layer = setup.profile->max_cells() * setup.profile->grid();
  cs.first_layer = std::clamp(printer->first_layer_height, cs.min_layer, cs.max_layer);
  cs.step = setup.profile->grid();
  const auto work = std::filesystem::temp_directory_path() / ("salient-cura-" + std::to_string(::getpid()));
  std::string why;
  core::ComparisonRow row;
  row.planner = "cura";
  std::optional<CuraPlan> cura;
  std::optional<ScoredFile> scored;
  try {  // a peer that fails leaves its row saying why, not the table unprinted
    cura = cura_adaptive_plan(setup.model.loaded.mesh, cs, work, why);
    if (cura) scored = score_file(cura->layers, *setup.profile, "CuraEngine's G-code");
  } catch (const core::InputError& e) {
    why = std::string("failed: ") + e.what();
  }
  if (!scored) {
    row.note = "skipped: " + why;
    c.rows.push_back(row);
    return;
  }
  const ScoredFile& f = *scored;
  const std::string_view exact[] = {"exact"};
  const core::Comparison at = core::compare_with_plan(base, f.given.plan, "cura", exact);
  row.layers_at_count = at.rows[0].layers_at_count;
  row.rsmd_at_count = at.rows[0].rsmd_at_count;
  row.layers_at_rsmd = at.rows[0].layers_at_rsmd;
  row.rsmd_at_rsmd = at.rows[0].rsmd_at_rsmd;
  row.seconds = cura->seconds;
  char note[160];
  std::snprintf(note, sizeof note,
                "its own count; exact at %d layers: RSMD %.4f, exact for Cura's RSMD: %d layers",
                at.rows[1].layers_at_count, at.rows[1].rsmd_at_count, at.rows[1].layers_at_rsmd);
  row.note = note;
  if (f.given.outside_limits > 0) row.note += "; " + limits_note(f.given);
  c.rows.push_back(std::move(row));
  std::filesystem::remove_all(work);
}

nlohmann::json rows_json(const core::Comparison& c) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : c.rows)
    rows.push_back({{"planner", r.planner},
                    {"layers_at_count", r.layers_at_count},
                    {"rsmd_at_count", r.rsmd_at_count},
                    {"layers_at_rsmd", r.layers_at_rsmd},
                    {"rsmd_at_rsmd", r.rsmd_at_rsmd},
                    {"seconds", r.seconds},
                    {"note", r.note}});
  return rows;
}

void print_rows(const core::Comparison& c) {
  std::printf("%-16s %14s %16s %9s  %s\n", "planner", "RSMD @ layers", "layers @ RSMD", "seconds", "note");
  for (const auto& r : c.rows) {
    if (r.layers_at_count > 0)
      std::printf("%-16s %8.4f @%4d %9d (%.4f) %9.3f  %s\n", r.planner.c_str(), r.rsmd_at_count,
                  r.layers_at_count, r.layers_at_rsmd, r.rsmd_at_rsmd, r.seconds, r.note.c_str());
    else if (r.layers_at_rsmd > 0)  // the segopt rows: at ρ only
      std::printf("%-16s %14s %9d (%.4f) %9.3f  %s\n", r.planner.c_str(), "-", r.layers_at_rsmd,
                  r.rsmd_at_rsmd, r.seconds, r.note.c_str());
    else  // a peer that did not run
      std::printf("%-16s %14s %16s %9s  %s\n", r.planner.c_str(), "-", "-", "-", r.note.c_str());
  }
}

// `compare MODEL --plan FILE`: the file's plan first, every planner at its count and its loss.
int compare_plan_file(const core::PlanningSetup& setup, const core::PlanRequest& base,
                      const std::string& path, const std::string& model, bool json, const std::string& metric,
                      const std::string& saliency) {
  const core::PlanFile file = core::read_plan_file(path);
  const std::string name = std::filesystem::path(path).filename().string();
  const ScoredFile f = score_file(file, *setup.profile, name);
  core::Comparison c = core::compare_with_plan(base, f.given.plan, "given", core::planner_names());
  c.rows[0].note = limits_note(f.given);
  if (json) {
    const nlohmann::json j = {{"model", model},
                              {"metric", metric},
                              {"saliency", saliency},
                              {"plan",
                               {{"file", name},
                                {"format", f.format},
                                {"layers", f.given.plan.layer_count()},
                                {"rsmd", c.reference_rsmd},
                                {"top", f.given.top},
                                {"outside_limits", f.given.outside_limits}}},
                              {"fine_layers", c.fine_layers},
                              {"coarse_layers", c.coarse_layers},
                              {"rows", rows_json(c)}};
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("%s: %s metric, %s saliency; %s (%s, top %.3f mm): %d layers, RSMD %.4f (fine %d, coarse %d)\n",
              model.c_str(), metric.c_str(), saliency.c_str(), name.c_str(), f.format.c_str(), f.given.top,
              c.reference_layers, c.reference_rsmd, c.fine_layers, c.coarse_layers);
  print_rows(c);
  return 0;
}

}  // namespace

void add_compare_command(CLI::App& app, CommandAction& action) {
  struct CompareOptions {
    core::Settings settings;  // as given on the command line
    SettingOptions given;
    core::PlanOptions plan;  // settings.slice.plan once applied
    bool json = false;
    std::string plan_file;
    bool peers = false;
  };
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Compare every planner on one model (the paper's Table 1)");
  o->given = add_plan_options(*cmd, o->settings, o->json, core::for_compare);
  cmd->add_option(
      "--plan", o->plan_file,
      "Score this plan instead of exact's at rho: our plan JSON, G-code (PrusaSlicer, Cura, ours) or a "
      "PrusaSlicer 3MF with a layer-height profile");
  cmd->add_flag("--peers", o->peers, "Add a row for Cura's adaptive layers (where CuraEngine is installed)");
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
      const std::string name = std::filesystem::path(o->plan.mesh.model).filename().string();
      const std::string metric(core::to_string(o->plan.metric)),
          saliency(core::to_string(core::saliency_method(o->plan)));  // a saliency file's is painted
      if (!o->plan_file.empty())
        return compare_plan_file(*setup, base, o->plan_file, name, o->json, metric, saliency);
      core::Comparison c = core::compare_planners(base, setup->rho, core::planner_names());
      // What `plan` makes with the same settings: its objective (time by default) may take a few
      // more layers than the fewest, for a quicker print. Said beside the fewest, so the two agree.
      int plan_layers = c.reference_layers;
      if (setup->goal != core::PlanGoal::layers)
        plan_layers = core::make_planner(o->plan.planner)
                          ->plan(setup->request(core::target_of(o->plan, *setup)))
                          .plan.layer_count();
      const std::string objective(core::to_string(setup->goal));
      add_segopt_rows(*setup, c);
      if (o->peers) add_cura_row(*setup, base, c);
      if (o->json) {
        const nlohmann::json rows = rows_json(c);
        nlohmann::json trace = nlohmann::json::array();
        for (const auto& s : c.adapslice_trace)
          trace.push_back({{"step", s.step}, {"layers", s.layers}, {"E", s.error}});
        const nlohmann::json j = {{"model", name},
                                  {"metric", std::string(core::to_string(o->plan.metric))},
                                  {"saliency", saliency},
                                  {"rho", c.rho},
                                  {"epsilon", c.epsilon},
                                  {"reference_layers", c.reference_layers},
                                  {"plan_layers", plan_layers},
                                  {"plan_objective", objective},
                                  {"reference_rsmd", c.reference_rsmd},
                                  {"fine_layers", c.fine_layers},
                                  {"coarse_layers", c.coarse_layers},
                                  {"rows", rows},
                                  {"adapslice_trace", trace}};
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
      }
      std::printf(
          "%s: %s metric, %s, rho %.3g; exact needs %d layers at fewest (fine %d, coarse %d), RSMD %.4f",
          name.c_str(), metric.c_str(), core::saliency_text(o->plan).c_str(), c.rho, c.reference_layers,
          c.fine_layers, c.coarse_layers, c.reference_rsmd);
      if (plan_layers != c.reference_layers)
        std::printf("; `plan` makes %d (--objective %s: the quicker print)", plan_layers, objective.c_str());
      std::printf("\n");
      print_rows(c);
      std::printf("adapslice trace:");
      for (const auto& s : c.adapslice_trace)
        std::printf(" %s %d (E %.4g);", s.step.c_str(), s.layers, s.error);
      std::printf("\n");
      return 0;
    };
  });
}

}  // namespace salient::cli
