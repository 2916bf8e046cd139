// `salient slice MODEL -o out.gcode`: core::slice_model (load, place, saliency, plan, toolpaths,
// G-code) with a progress line on a terminal.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "clients/cli/setting_options.hpp"
#include "core/common/input_error.hpp"
#include "core/pipeline/plan_report.hpp"
#include "core/pipeline/slice_pipeline.hpp"
#include "core/pipeline/slice_result_json.hpp"

namespace salient::cli {
namespace {

struct SliceOptions {
  core::Settings settings;  // as given on the command line
  SettingOptions given;
  bool json = false;
  std::string output;
};

core::ProgressFn progress_line() {
  if (!isatty(STDERR_FILENO)) return {};
  return [](std::string_view phase, double fraction) {
    std::fprintf(stderr, "\r%-10.*s %3.0f%%", static_cast<int>(phase.size()), phase.data(), 100 * fraction);
    if (fraction >= 1) std::fprintf(stderr, "\n");
  };
}

void write_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out) throw core::InputError(path, {}, "cannot write");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw core::InputError(path, {}, "cannot write");
}

}  // namespace

void add_slice_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<SliceOptions>();
  CLI::App* cmd = app.add_subcommand("slice", "Plan the layers of a model and write G-code for a printer");
  o->given = add_plan_options(*cmd, o->settings, o->json, core::for_slice);
  cmd->add_option("-o,--output", o->output, "G-code file to write")->required();
  cmd->callback([o, &action] {
    action = [o] {
      o->given.apply(o->settings);
      const core::PrinterProfile printer = resolve_printer(o->settings.printer);
      const core::SliceSettings& settings = o->settings.slice;
      const auto t0 = std::chrono::steady_clock::now();
      const core::SliceResult r =
          core::slice_model(settings, printer, core::RunContext{nullptr, progress_line()});
      write_atomically(o->output, r.gcode);
      if (o->json) {  // the job result's figures, by the same writer
        std::fputs(core::slice_result_json(r, printer.id, cli_flag, 2).c_str(), stdout);
        return 0;
      }
      if (r.orientation) print_orientation(*r.orientation);
      if (r.segmentation) {
        std::printf("segmentation: %s; whole %.1f min, parts %.1f min, result %.1f min\n",
                    r.segmentation->note.c_str(), r.segmentation->whole_seconds / 60,
                    r.segmentation->parts_seconds / 60, r.segmentation->seconds / 60);
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf(
          "%s: %d layers (finest %d, %.1f%% fewer), RSMD %.4f, for %s; print %s, %.2f m filament; "
          "sliced in %.2f s "
          "-> %s\n",
          r.model_name.c_str(), r.layers, r.finest_layers, 100.0 * (1 - double(r.layers) / r.finest_layers),
          r.rsmd, printer.name.c_str(), core::duration_text(r.print_seconds).c_str(), r.filament_mm / 1000,
          seconds, o->output.c_str());
      if (r.plan.times)
        std::printf("against uniform layers (%s): %s\n",
                    r.segmentation ? "each one's G-code" : "the time model, scaled to this G-code's estimate",
                    core::times_text(*r.plan.times, r.plan.min_layer, r.rsmd).c_str());
      for (const core::SliceWarning& w : r.warnings)
        std::printf("warning: %s\n", core::spell_settings(w.message, cli_flag).c_str());
      return 0;
    };
  });
}

}  // namespace salient::cli
