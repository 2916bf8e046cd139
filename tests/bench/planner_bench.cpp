// Planner benchmark: z-profile build, `exact` at ρ and at a fixed count, and the full
// comparison (the paper's Table 1), per model, median of repeated runs.
// Usage: planner_bench [--runs N] [--metric area|paper] MODEL:UP ...   (UP is x, y or z)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/mesh_loader.hpp"
#include "core/mesh/placement.hpp"
#include "core/slicing/comparison.hpp"
#include "core/slicing/exact_solver.hpp"

using namespace salient::core;

namespace {

template <typename F>
double median_seconds(int runs, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5;
  Metric metric = Metric::area;
  std::vector<std::string> models;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
      runs = std::max(1, std::atoi(argv[++i]));
    else if (std::strcmp(argv[i], "--metric") == 0 && i + 1 < argc)
      metric = *parse_metric(argv[++i]);
    else
      models.emplace_back(argv[i]);
  }
  std::printf("metric %s, 80 mm, alpha 0.1, alpha_max 0.4, grid 0.01, rho 0.05, median of %d\n",
              std::string(metric_name(metric)).c_str(), runs);
  std::printf("%-22s %8s %10s %10s %8s %12s %12s\n", "model", "faces", "profile s", "exact s", "layers",
              "exact@N s", "compare s");
  for (const std::string& spec : models) {
    const auto colon = spec.rfind(':');
    const std::string path = spec.substr(0, colon);
    LoadedMesh m = load_mesh(std::filesystem::path(path));
    PlacementOptions o;
    o.up = *parse_up_axis(colon == std::string::npos ? "z" : spec.substr(colon + 1));
    o.target_height = 80;
    place_mesh(m.mesh, o);
    const std::vector<float> s(m.mesh.vertex_count(), 1.0f);
    const double t_profile = median_seconds(runs, [&] { ZProfile::build(m.mesh, s, {}); });
    const ZProfile profile = ZProfile::build(m.mesh, s, {});
    const Objective obj(profile, metric), geo(profile, metric, true);
    int layers = 0;
    const double t_exact = median_seconds(runs, [&] {
      ExactSolver solver(obj);
      layers = solver.fewest_layers_within(obj.sm_fine() + obj.epsilon(0.05));
      solver.plan(layers);
    });
    const double t_fixed = median_seconds(runs, [&] {
      ExactSolver solver(obj);
      solver.plan(profile.most_layers() * 3 / 4);
    });
    const PlanRequest base{obj, &m.mesh, &geo, {}, 1, {}};
    const double t_compare = median_seconds(1, [&] { compare_planners(base, 0.05, planner_names()); });
    std::printf("%-22s %8zu %10.3f %10.3f %8d %12.3f %12.3f\n",
                std::filesystem::path(path).filename().c_str(), m.mesh.triangle_count(), t_profile, t_exact,
                layers, t_fixed, t_compare);
  }
  return 0;
}
