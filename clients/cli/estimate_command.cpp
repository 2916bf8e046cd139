// `salient estimate FILE.gcode`: print time (trapezoidal acceleration, per-axis jerk), per
// layer, and filament, for any G-code file; and the stream it needs: the busiest second's
// commands against what a serial link at the printer's baud rate carries (core/gcode/stream_demand).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "core/gcode/stream_demand.hpp"
#include "core/gcode/time_estimator.hpp"
#include "core/printer/printer_profile.hpp"

namespace salient::cli {
namespace {

struct EstimateOptions {
  std::string file;
  std::string printer;
  bool json = false;
};

std::string hms(double seconds) {
  const long s = std::lround(seconds);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%ldh %02ldm %02lds", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

nlohmann::json stream_json(const core::StreamDemand& s) {
  return {{"peak_commands_per_second", s.peak_commands_per_second},
          {"peak_at_seconds", s.peak_at_seconds},
          {"mean_framed_bytes", s.mean_framed_bytes},
          {"baud", s.baud},
          {"link_commands_per_second", s.link_commands_per_second},
          {"starves", s.starves()}};
}

}  // namespace

core::PrinterProfile resolve_printer(const std::string& spec) {
  if (spec.ends_with(".toml") || std::filesystem::exists(spec)) return core::load_printer_profile(spec);
  if (auto p = core::builtin_printer(spec)) return *p;
  std::string known;
  for (const std::string& id : core::builtin_printer_ids()) known += (known.empty() ? "" : ", ") + id;
  throw core::InputError("--printer", {},
                         "unknown printer '" + spec + "' (built in: " + known + "; or a .toml file)");
}

void add_estimate_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<EstimateOptions>();
  CLI::App* cmd = app.add_subcommand("estimate", "Estimate the print time of a G-code file");
  cmd->add_option("FILE", o->file, "G-code file")->required();
  cmd->add_option("--printer", o->printer,
                  "Printer profile (built-in id or .toml) for acceleration, jerk and the link's baud rate");
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->callback([o, &action] {
    action = [o] {
      core::MachineLimits limits;
      int baud = core::PrinterProfile{}.baud;
      if (!o->printer.empty()) {
        const core::PrinterProfile p = resolve_printer(o->printer);
        limits.acceleration = limits.travel_acceleration = limits.retract_acceleration = p.acceleration;
        limits.jerk[0] = limits.jerk[1] = p.jerk;
        baud = p.baud;
      }
      const std::string name = std::filesystem::path(o->file).filename().string();
      std::ifstream in(o->file, std::ios::binary);
      if (!in) throw core::InputError(name, {}, "cannot open for reading");
      std::ostringstream text;
      text << in.rdbuf();
      std::vector<core::CommandTiming> commands;
      const core::GcodeEstimate e = core::estimate_gcode(text.str(), name, limits, &commands);
      const core::StreamDemand stream = core::stream_demand(commands, baud);
      if (o->json) {
        const nlohmann::json j = {{"file", name},
                                  {"seconds", e.seconds},
                                  {"layers", e.layer_seconds.size()},
                                  {"layer_seconds", e.layer_seconds},
                                  {"filament_mm", e.filament_mm},
                                  {"moves", e.moves},
                                  {"lines", e.lines},
                                  {"heating_waits", e.heating_waits},
                                  {"stream", stream_json(stream)}};
        std::printf("%s\n", j.dump(2).c_str());
      } else {
        std::printf("%s: %s (%.0f s) over %zu layers, %.1f m of filament, %zu moves%s\n", name.c_str(),
                    hms(e.seconds).c_str(), e.seconds, e.layer_seconds.size(), e.filament_mm / 1000, e.moves,
                    e.heating_waits ? ", plus heating" : "");
        std::printf(
            "stream: at most %.0f commands in one second (at %s), %.1f bytes each framed; a %d-baud "
            "link carries %.0f/s (N… *sum lines, each waiting for its ok; no USB latency)\n",
            stream.peak_commands_per_second, hms(stream.peak_at_seconds).c_str(), stream.mean_framed_bytes,
            stream.baud, stream.link_commands_per_second);
      }
      if (stream.starves())
        std::fprintf(
            stderr,
            "warning: %s needs %.0f commands per second, more than a %d-baud link carries (%.0f): the "
            "printer's planner would starve (stutter, blobs)\n",
            name.c_str(), stream.peak_commands_per_second, stream.baud, stream.link_commands_per_second);
      return 0;
    };
  });
}

}  // namespace salient::cli
