// PlanDocument: a layer plan as salient hands it on. `salient plan -o`, `salient plan --segment -o`
// and the daemon's GET /api/v1/jobs/{id}/plan all write it, in one versioned JSON format
// ("format": "salient-plan", "version": 1; docs/plan-format.md, docs/plan.schema.json), and
// `salient export-3mf` reads it (core/export/plan_json). Plain and segmented plans share it: the
// printed layers are always `layers`; a segmented plan adds its SegOpt report.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace salient::core {

struct PlanLayer {
  double z_bottom = 0, z_top = 0, height = 0;  // mm
  // A single-region plan's layers as the objective sees them (core::LayerReport): largest
  // saliency, largest |n_z|, SM(L). A segmented plan's printed layers mix regions: none.
  std::optional<double> saliency, cos, sm;
};

struct PlanTraceStep {  // adapslice's steps
  std::string step;
  int layers = 0;
  double error = 0;
};

// What SegOpt decided (core::SegOptResult, in mm instead of grid cells).
struct SegmentationReport {
  struct Region {
    int side = -1;  // -1: the whole section; 0 or 1: that side of the first cut
    std::vector<int> sub;
    double z_bottom = 0, z_top = 0;
    int layers = 0;
    double error = 0, epsilon = 0;
    std::vector<double> boundaries;           // z of its layer boundaries, mm, bottom first
    std::vector<std::array<double, 2>> clip;  // the XY area it prints (empty: all of it)
  };
  struct Slab {
    double z_bottom = 0, z_top = 0;
    bool merged = false;
    std::array<double, 2> loss{0, 0};
  };
  struct Plane {  // core::SeamCandidate
    double nx = 1, ny = 0, offset = 0, cost = 0, seam_mean = 0, difference = 0, length = 0, share = 0;
  };
  bool cut = false;
  std::string note;
  double whole_seconds = 0, parts_seconds = 0, seconds = 0;  // estimated print times
  std::vector<Region> regions;
  std::vector<Slab> slabs;
  std::optional<Plane> plane;
};

// Estimated printing times (LayerTimeModel, s): the plan, uniform at the finest layer (the
// paper's baseline) and uniform at the printer's default height (what a user would print
// otherwise), with that plan's RSMD — "how much faster, and at what visible cost" in one line.
// The uniform plans keep the same fixed first layer.
struct PlanTimes {
  double plan_seconds = 0;
  int fine_layers = 0;
  double fine_seconds = 0;
  double default_layer_height = 0;  // mm
  int default_layers = 0;
  double default_seconds = 0, default_rsmd = 0;

  double saving_vs_fine() const { return fine_seconds - plan_seconds; }  // s
  // All three times × k (their ratios, the savings in per cent, kept).
  void scale(double k) { plan_seconds *= k, fine_seconds *= k, default_seconds *= k; }
  double saving_vs_default() const { return default_seconds - plan_seconds; }
  double saving_vs_fine_percent() const {
    return fine_seconds > 0 ? 100 * saving_vs_fine() / fine_seconds : 0;
  }
  double saving_vs_default_percent() const {
    return default_seconds > 0 ? 100 * saving_vs_default() / default_seconds : 0;
  }
};

struct PlanDocument {
  static constexpr const char* format = "salient-plan";
  static constexpr int version = 1;  // what this salient writes and the newest it reads

  std::string model;  // the model's file name
  std::string planner, metric;
  std::string objective;  // what `exact` minimised: "time" or "layers" (empty: not recorded)
  // The saliency that weighed the plan, as saliency_text names it: "spectral saliency", "painted
  // saliency from F" (empty: not recorded).
  std::string saliency_method;
  double height = 0;                              // the placed model's height, mm
  double grid = 0, min_layer = 0, max_layer = 0;  // mm
  int fine_layers = 0, coarse_layers = 0;         // all layers at min_layer, at max_layer
  double error = 0, rsmd = 0;                     // E and RSMD of the whole plan
  std::optional<double> epsilon, rho;             // the quality target, when planned to one
  std::optional<int> requested_layers;            // the layer count asked for, when so planned
  double seconds = 0;                             // time taken to plan
  std::vector<PlanLayer> layers;                  // the printed layers, bottom up
  std::string note;                               // the planner's remark, if any
  std::vector<PlanTraceStep> trace;
  std::optional<SegmentationReport> segmentation;  // a segmented plan's
  std::optional<PlanTimes> times;                  // estimated printing times, when known

  int count() const { return static_cast<int>(layers.size()); }
  // The layer boundaries, mm: the bed (0), then each layer's top.
  std::vector<double> boundaries() const {
    std::vector<double> z{0};
    for (const PlanLayer& l : layers) z.push_back(l.z_top);
    return z;
  }
};

}  // namespace salient::core
