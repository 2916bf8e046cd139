// Objective: plan-level sums of the layer metric.
#include "core/slicing/objective.hpp"

namespace salient::core {

const std::vector<std::string_view>& metric_names() {
  static const std::vector<std::string_view> names = {"area", "paper"};  // Metric's order
  return names;
}

std::optional<Metric> parse_metric(std::string_view name) {
  const auto& names = metric_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<Metric>(i);
  return std::nullopt;
}

std::string_view metric_name(Metric metric) {
  return metric_names().at(static_cast<std::size_t>(metric));
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
