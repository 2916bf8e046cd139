// Objective: plan-level sums of the layer metric.
#include "core/slicing/objective.hpp"

namespace salient::core {

std::optional<Metric> parse_metric(std::string_view name) {
  if (name == "area") return Metric::area;
  if (name == "paper") return Metric::paper;
  return std::nullopt;
}

std::string_view metric_name(Metric metric) {
  return metric == Metric::area ? "area" : "paper";
}

Objective::Objective(const ZProfile& profile, Metric metric, bool geometric)
    : profile_(profile), metric_(metric), geometric_(geometric), channel_(profile.channel(geometric)) {
  sm_fine_ = sm(fine_plan(profile));
  e_coarse_ = sm(coarse_plan(profile)) - sm_fine_;
}

double Objective::sm(const LayerPlan& plan) const {
  double total = 0;
  for (int i = 0; i < plan.layer_count(); ++i) total += layer_sm(plan.boundaries[i], plan.boundaries[i + 1]);
  return total;
}

std::vector<LayerReport> Objective::layers(const LayerPlan& plan) const {
  std::vector<LayerReport> out;
  out.reserve(plan.layer_count());
  for (int i = 0; i < plan.layer_count(); ++i) {
    const int a = plan.boundaries[i], b = plan.boundaries[i + 1];
    out.push_back({profile_.z(a), profile_.z(b), profile_.z(b) - profile_.z(a), channel_.S_max(a, b),
                   profile_.max_cos(a, b), layer_sm(a, b)});
  }
  return out;
}

}  // namespace salient::core
