// The planner registry: names as the CLI, the daemon and `compare` use them.
#include "core/slicing/planner.hpp"

#include "core/slicing/planners/planners.hpp"

namespace salient::core {

const std::vector<std::string_view>& planner_names() {
  static const std::vector<std::string_view> names = {
      "exact", "adapslice", "hms", "uniform", "cusp", "stepwise", "ha13", "ceo", "random", "fine", "coarse"};
  return names;
}

std::unique_ptr<Planner> make_planner(std::string_view name) {
  using namespace planners;
  if (name == "exact") return make_exact();
  if (name == "adapslice") return make_adapslice();
  if (name == "hms") return make_hms();
  if (name == "uniform") return make_uniform();
  if (name == "cusp") return make_cusp();
  if (name == "stepwise") return make_stepwise();
  if (name == "ha13") return make_ha13();
  if (name == "ceo") return make_ceo();
  if (name == "random") return make_random();
  if (name == "fine") return make_fine();
  if (name == "coarse") return make_coarse();
  return nullptr;
}

}  // namespace salient::core
