// The planner registry: names as the CLI, the daemon and `compare` use them.
#include "core/slicing/planner.hpp"

#include "core/slicing/planners/planners.hpp"

namespace salient::core {

const std::vector<std::string_view>& planner_names() {
  static const std::vector<std::string_view> names = {
      "exact", "adapslice", "hms", "uniform", "cusp", "stepwise", "ha13", "ceo", "random", "fine", "coarse"};
  return names;
}

std::optional<PlannerKind> parse_planner(std::string_view name) {
  const auto& names = planner_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<PlannerKind>(i);
  return std::nullopt;
}

std::string_view to_string(PlannerKind kind) {
  return planner_names().at(static_cast<std::size_t>(kind));
}

const std::vector<std::string_view>& plan_goal_names() {
  static const std::vector<std::string_view> names = {"time", "layers"};  // PlanGoal's order
  return names;
}

std::optional<PlanGoal> parse_plan_goal(std::string_view name) {
  const auto& names = plan_goal_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<PlanGoal>(i);
  return std::nullopt;
}

std::string_view to_string(PlanGoal goal) {
  return plan_goal_names().at(static_cast<std::size_t>(goal));
}

namespace {

std::unique_ptr<Planner> make_own_planner(PlannerKind kind) {
  using namespace planners;
  switch (kind) {
    case PlannerKind::exact:
      return make_exact();
    case PlannerKind::adapslice:
      return make_adapslice();
    case PlannerKind::hms:
      return make_hms();
    case PlannerKind::uniform:
      return make_uniform();
    case PlannerKind::cusp:
      return make_cusp();
    case PlannerKind::stepwise:
      return make_stepwise();
    case PlannerKind::ha13:
      return make_ha13();
    case PlannerKind::ceo:
      return make_ceo();
    case PlannerKind::random:
      return make_random();
    case PlannerKind::fine:
      return make_fine();
    case PlannerKind::coarse:
      return make_coarse();
  }
  return nullptr;
}

}  // namespace

std::unique_ptr<Planner> make_planner(PlannerKind kind) {
  auto own = make_own_planner(kind);
  return own ? planners::with_first_layer(std::move(own)) : nullptr;
}

std::unique_ptr<Planner> make_planner(std::string_view name) {
  const auto kind = parse_planner(name);
  return kind ? make_planner(*kind) : nullptr;
}

}  // namespace salient::core
