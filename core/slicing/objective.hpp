// Objective: the saliency metric of a layer and of a plan, and the quality loss E against the
// finest plan (paper §3, eqs. 1–3; ALGORITHMS.md §3).
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "core/slicing/layer_plan.hpp"
#include "core/slicing/z_profile.hpp"

namespace salient::core {

enum class Metric {
  area,   // ours: SM(L) = h/2 · Σ_{k∈L} A[k], the saliency-weighted stair-step volume
  paper,  // eq. 1: SM(L) = S_L · h · cos θ_L, S_L and cos θ_L maxima over the layer's cells
};

// The name table: "area", "paper" (in this order), and back.
const std::vector<std::string_view>& metric_names();
std::optional<Metric> parse_metric(std::string_view name);
std::string_view metric_name(Metric metric);
inline std::string_view to_string(Metric metric) {
  return metric_name(metric);
}

struct LayerReport {
  double z_bottom, z_top, height;  // mm
  double saliency;                 // S_L: largest saliency in the layer
  double cos;                      // cos θ_L: largest |n_z| in the layer
  double sm;                       // SM(L) under the objective's metric
};

class Objective {
 public:
  // `geometric`: use the saliency ≡ 1 field (the `ceo` planner's view of the model).
  Objective(const ZProfile& profile, Metric metric, bool geometric = false);

  const ZProfile& profile() const { return profile_; }
  Metric metric() const { return metric_; }
  bool geometric() const { return geometric_; }

  // SM of the layer spanning cells [i, j).
  double layer_sm(int i, int j) const {
    const double h = profile_.z(j) - profile_.z(i);
    if (metric_ == Metric::area) return 0.5 * h * (channel_.A_prefix[j] - channel_.A_prefix[i]);
    return h * channel_.S_max(i, j) * profile_.max_cos(i, j);
  }
  double sm(const LayerPlan& plan) const;                                    // eq. 2
  double error(const LayerPlan& plan) const { return sm(plan) - sm_fine_; }  // E, eq. 3
  double rsmd(const LayerPlan& plan) const { return e_coarse_ > 0 ? error(plan) / e_coarse_ : 0; }
  double sm_fine() const { return sm_fine_; }
  double e_coarse() const { return e_coarse_; }                 // E of uniform ᾱ
  double epsilon(double rho) const { return rho * e_coarse_; }  // ε = ρ · E(coarse)

  std::vector<LayerReport> layers(const LayerPlan& plan) const;

 private:
  const ZProfile& profile_;
  Metric metric_;
  bool geometric_;
  const ProfileChannel& channel_;
  double sm_fine_ = 0, e_coarse_ = 0;
};

}  // namespace salient::core
