// Calibration of the layer time model (core/slicing/layer_time_model) against estimate_gcode on
// real G-code: each model is sliced (generic-i3, 80 mm, uniform saliency: times do not depend on
// it) with exact and with uniform 0.1 and 0.2 mm; every 12 layers above the first (whose time holds
// the start code) are one sample. Prints the error of the model's totals with its built-in factors,
// then the least-squares factors (seconds = overhead + Σ factor·length/speed + per-line·lines)
// and the error with them. Usage: time_model_bench MODEL:UP ...
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/gcode/time_estimator.hpp"
#include "core/pipeline/slice_pipeline.hpp"

using namespace salient::core;

namespace {

constexpr int k = 7;  // overhead, walls, solid, sparse, lines, travel, combined travel

struct Fit {
  double a[k][k] = {}, b[k] = {};
  void add(const double (&x)[k], double y) {
    for (int i = 0; i < k; ++i) {
      b[i] += x[i] * y;
      for (int j = 0; j < k; ++j) a[i][j] += x[i] * x[j];
    }
  }
  std::vector<double> solve() const {  // Gaussian elimination with partial pivoting
    double m[k][k + 1];
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) m[i][j] = a[i][j];
      m[i][k] = b[i];
    }
    for (int c = 0; c < k; ++c) {
      int p = c;
      for (int r = c + 1; r < k; ++r)
        if (std::fabs(m[r][c]) > std::fabs(m[p][c])) p = r;
      for (int j = 0; j <= k; ++j) std::swap(m[c][j], m[p][j]);
      for (int r = 0; r < k; ++r)
        if (r != c) {
          const double f = m[r][c] / m[c][c];
          for (int j = c; j <= k; ++j) m[r][j] -= f * m[c][j];
        }
    }
    std::vector<double> x(k);
    for (int i = 0; i < k; ++i) x[i] = m[i][k] / m[i][i];
    return x;
  }
};

struct Sample {
  double x[k];
  double y;
};

struct Run {
  std::string name;
  std::vector<Sample> samples;
  double estimate = 0, model = 0;  // seconds, layers above the first
};

// The regressors of one layer, with the speed the minimum layer time leaves.
void regressors(const LayerTimeModel& m, int i, int j, double (&x)[k]) {
  const TimeModelParams& p = m.params();
  const LayerFeatures f = m.features(i, j);
  double speed = f.first ? p.first_layer_speed : p.print_speed;
  const double nominal = (f.wall_length + f.solid_length + f.sparse_length) / speed;
  if (nominal > 0 && nominal < p.min_layer_time)
    speed = std::max(speed * nominal / p.min_layer_time, std::min(speed, p.min_print_speed));
  x[0] = 1;
  x[1] = f.wall_length / speed;
  x[2] = f.solid_length / speed;
  x[3] = f.sparse_length / speed;
  x[4] = f.infill_lines;
  x[5] = std::sqrt(f.section_area) / p.travel_speed;
  x[6] = f.combined ? x[5] : 0;
}

Run slice_and_sample(const std::string& model, const std::string& up, PlannerKind planner,
                     double layer_height, const PrinterProfile& printer) {
  SliceSettings s;
  s.plan.mesh.model = model;
  s.plan.mesh.up = up;
  s.plan.mesh.height = 80;
  s.plan.planner = planner;
  if (layer_height > 0) s.plan.layer_height = layer_height;
  const SliceResult r = slice_model(s, printer, {});
  // The planning setup as slice_model builds it, for the model's view of the same layers.
  PlanOptions o = s.plan;
  o.min_layer = printer.min_layer;
  o.max_layer = printer.max_layer;
  o.mesh.bed_center_x = printer.bed_center_x();
  o.mesh.bed_center_y = printer.bed_center_y();
  ToolpathSettings tp = s.toolpaths;
  tp.combine_infill_up_to = printer.max_layer;
  o.time_model = time_model_params(printer, tp, GcodeSettings{});
  const auto setup = prepare(o);
  const GcodeEstimate e = estimate_gcode(r.gcode, model);
  Run run;
  run.name = std::filesystem::path(model).filename().string() + " " + std::string(to_string(planner)) +
             (layer_height > 0 ? " " + std::to_string(layer_height).substr(0, 3) : "");
  std::vector<int> b{0};
  for (double z : r.z) b.push_back(static_cast<int>(std::lround(z / setup->profile->grid())));
  b.back() = setup->profile->cells();
  if (e.layer_seconds.size() != r.z.size()) {
    std::fprintf(stderr, "%s: %zu estimated layers for %zu planned\n", run.name.c_str(),
                 e.layer_seconds.size(), r.z.size());
    return run;
  }
  for (std::size_t l = 1; l + 1 < b.size(); ++l) {
    Sample smp;
    regressors(*setup->time, b[l], b[l + 1], smp.x);
    smp.y = e.layer_seconds[l];
    if (std::getenv("TIME_MODEL_DUMP") && l % 40 == 0)
      std::printf(
          "  %s layer %zu z %.2f h %.2f: est %.2f s; 1/v·walls %.2f solid %.2f sparse %.2f; lines %.1f; "
          "model %.2f\n",
          run.name.c_str(), l, b[l + 1] * setup->profile->grid(), (b[l + 1] - b[l]) * setup->profile->grid(),
          smp.y, smp.x[1], smp.x[2], smp.x[3], smp.x[4], setup->time->layer_seconds(b[l], b[l + 1]));
    // Samples of 12 consecutive layers: combined sparse infill lands on every second, third or
    // fourth layer, and the estimator's look-ahead moves time across layer changes.
    if (run.samples.empty() || (l - 1) % 12 == 0)
      run.samples.push_back(smp);
    else {
      for (int q = 0; q < k; ++q) run.samples.back().x[q] += smp.x[q];
      run.samples.back().y += smp.y;
    }
    run.estimate += smp.y;
    run.model += setup->time->layer_seconds(b[l], b[l + 1]);
  }
  return run;
}

double predict(const std::vector<double>& c, const Sample& s) {
  double t = 0;
  for (int i = 0; i < k; ++i) t += c[i] * s.x[i];
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const PrinterProfile printer = *builtin_printer("generic-i3");
  std::vector<Run> runs;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const auto colon = arg.rfind(':');
    const std::string model = arg.substr(0, colon),
                      up = colon == std::string::npos ? "z" : arg.substr(colon + 1);
    runs.push_back(slice_and_sample(model, up, PlannerKind::exact, 0, printer));
    runs.push_back(slice_and_sample(model, up, PlannerKind::uniform, 0.1, printer));
    runs.push_back(slice_and_sample(model, up, PlannerKind::uniform, 0.2, printer));
  }
  Fit fit;
  // A run whose G-code is (nearly) empty — a mesh too broken to section — says nothing.
  std::erase_if(runs, [](const Run& r) {
    if (r.estimate > 0.2 * r.model) return false;
    std::printf("%s: left out, estimate %.0f s (broken sections)\n", r.name.c_str(), r.estimate);
    return true;
  });
  for (const Run& r : runs)
    for (const Sample& s : r.samples) fit.add(s.x, s.y);
  const std::vector<double> c = fit.solve();
  // The same fit with the per-layer overhead held at the built-in (physical) value, which the free
  // fit drives negative: y − overhead on the other six regressors.
  const TimeModelParams p;
  Fit held;
  for (const Run& r : runs)
    for (const Sample& s : r.samples) {
      double x[k];
      std::copy(std::begin(s.x), std::end(s.x), x);
      x[0] = 0;
      held.add(x, s.y - p.layer_overhead * s.x[0]);
    }
  held.a[0][0] = 1;  // x0 ≡ 0 left the first row empty: solve it as c0 = 0
  std::vector<double> h = held.solve();
  h[0] = p.layer_overhead;
  std::printf("built-in: overhead %.3f s, walls ×%.3f, solid ×%.3f, sparse ×%.3f, %.3f s per infill line\n",
              p.layer_overhead, p.wall_factor, p.solid_factor, p.sparse_factor, p.line_overhead);
  std::printf("fitted:   overhead %.3f s, walls ×%.3f, solid ×%.3f, sparse ×%.3f, %.3f s per infill line\n",
              c[0], c[1], c[2], c[3], c[4]);
  std::printf(
      "held:     overhead %.3f s, walls ×%.3f, solid ×%.3f, sparse ×%.3f, %.3f s per infill line; travel "
      "×%.2f, "
      "combined ×%.2f (fitted %.2f, %.2f)\n",
      h[0], h[1], h[2], h[3], h[4], h[5], h[6], c[5], c[6]);
  std::printf("%-28s %10s %10s %8s %10s %8s %10s\n", "run", "estimate", "model", "error", "fitted", "error",
              "MAE/12");
  double sum_abs = 0, sum_abs_fit = 0, sum_abs_held = 0;
  for (const Run& r : runs) {
    double fitted = 0, mae = 0, with_held = 0;
    for (const Sample& s : r.samples) {
      fitted += predict(c, s);
      with_held += predict(h, s);
      mae += std::fabs(predict(c, s) - s.y);
    }
    mae /= std::max<std::size_t>(1, r.samples.size());
    const double e1 = 100 * (r.model / r.estimate - 1), e2 = 100 * (fitted / r.estimate - 1);
    sum_abs += std::fabs(e1);
    sum_abs_fit += std::fabs(e2);
    sum_abs_held += std::fabs(100 * (with_held / r.estimate - 1));
    std::printf("%-28s %10.0f %10.0f %+7.1f%% %10.0f %+7.1f%% %9.2fs\n", r.name.c_str(), r.estimate, r.model,
                e1, fitted, e2, mae);
  }
  std::printf("mean |error| of totals: built-in %.1f %%, fitted %.1f %%, overhead held %.1f %%\n",
              sum_abs / runs.size(), sum_abs_fit / runs.size(), sum_abs_held / runs.size());
  return 0;
}
