// `salient saliency MODEL`: compute per-vertex saliency; write a heat-coloured PLY (quality =
// saliency) and a three-view PNG preview; print a summary or JSON.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "clients/cli/cli_options.hpp"
#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "core/mesh/ply_writer.hpp"
#include "core/render/saliency_preview.hpp"
#include "core/saliency/saliency.hpp"

namespace salient::cli {
namespace {

struct SaliencyOptions {
  core::MeshOptions mesh;
  std::string method = "spectral";
  std::string output, png;
  bool json = false;
};

}  // namespace

void add_saliency_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<SaliencyOptions>();
  CLI::App* cmd = app.add_subcommand("saliency", "Compute per-vertex saliency and write it for viewing");
  add_mesh_options(*cmd, o->mesh, true);
  cmd->add_option("--method", o->method, "spectral (the paper's), lee05, painted or uniform")
      ->check(CLI::IsMember({"spectral", "lee05", "painted", "uniform"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output,
                  "Write a PLY with saliency as vertex quality and a heat-map colour");
  cmd->add_option("--png", o->png, "Write a PNG preview (front, side and top views)");
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->callback([o, &action] {
    action = [o] {
      resolve_auto_up(o->mesh, nullptr, o->json);
      const core::PlacedModel m = core::load_placed(o->mesh);
      const std::string name = std::filesystem::path(o->mesh.model).filename().string();
      const core::Mesh surface = core::file_surface(m.loaded);  // without the caps repair added
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<float> s =
          core::compute_saliency(surface, *core::parse_saliency_method(o->method), name);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!o->output.empty()) {
        std::vector<core::Color> colors(s.size());
        std::transform(s.begin(), s.end(), colors.begin(), core::heat_color);
        core::write_ply(o->output, surface, s, colors);
      }
      if (!o->png.empty()) core::write_png(o->png, core::render_preview(surface, s));
      double mean = 0;
      for (float v : s) mean += v;
      mean /= std::max<std::size_t>(1, s.size());
      std::vector<float> sorted = s;
      std::sort(sorted.begin(), sorted.end());
      const auto quantile = [&](double q) {
        return sorted.empty() ? 0.0f : sorted[static_cast<std::size_t>(q * (sorted.size() - 1))];
      };
      if (o->json) {
        const nlohmann::json j = {{"model", name},        {"method", o->method}, {"vertices", s.size()},
                                  {"seconds", seconds},   {"mean", mean},        {"median", quantile(0.5)},
                                  {"p90", quantile(0.9)}, {"min", quantile(0)},  {"max", quantile(1)}};
        std::printf("%s\n", j.dump(2).c_str());
      } else {
        std::printf(
            "%s: %s saliency on %zu vertices in %.2f s; mean %.3f, median %.3f, 90th percentile %.3f\n",
            name.c_str(), o->method.c_str(), s.size(), seconds, mean, quantile(0.5), quantile(0.9));
      }
      return 0;
    };
  });
}

}  // namespace salient::cli
