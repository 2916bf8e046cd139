// hms: greedy merging by the metric's merge cost, the paper's initialisation (§4) and its
// "HMS" baseline (§7). ha13: greedy merging by the geometric error of Hayasi & Asiabanpour
// 2013 — the area of the XOR of a layer's bottom and top sections, times half its height
// (the volume of the stair step it leaves). Both merge from the finest plan; the number of
// merges is the parameter searched for each target.
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "core/geometry/mesh_section.hpp"
#include "core/geometry/polygon_ops.hpp"
#include "core/slicing/merge_sequence.hpp"
#include "core/slicing/planners/planners.hpp"

namespace salient::core::planners {
namespace {

PlanResult read_off(const PlanRequest& request, const MergeSequence& seq) {
  const Objective& obj = request.objective;
  PlanResult result;
  if (request.target.layers) {
    const int want = clamp_count(obj.profile(), *request.target.layers, result.note);
    result.plan = seq.at(want);
    if (result.plan.layer_count() != want && result.note.empty())
      result.note = "merging stops at " + std::to_string(seq.fewest()) +
                    " layers (no merge keeps layers within " + "the maximum thickness), so " +
                    std::to_string(result.plan.layer_count());
    return result;
  }
  const double budget = request.target.epsilon.value_or(0) - obj.error(seq.at(seq.most()));
  result.plan = seq.at(seq.fewest_within(budget));
  return result;
}

MergeSequence::Cost loss_of(const Objective& obj) {
  return [&obj](int i, int j, int k) { return obj.layer_sm(i, k) - obj.layer_sm(i, j) - obj.layer_sm(j, k); };
}

class HmsPlanner : public Planner {
 public:
  std::string_view name() const override { return "hms"; }
  PlanResult plan(const PlanRequest& request) const override {
    const Objective& obj = request.objective;
    const auto loss = loss_of(obj);
    const MergeSequence seq(fine_plan(obj.profile()), obj.profile().max_cells(), loss, loss, request.run);
    return read_off(request, seq);
  }
};

class Ha13Planner : public Planner {
 public:
  std::string_view name() const override { return "ha13"; }
  PlanResult plan(const PlanRequest& request) const override {
    if (!request.mesh) throw std::invalid_argument("ha13 needs the placed mesh");
    const Objective& obj = request.objective;
    const ZProfile& profile = obj.profile();
    const LayerPlan fine = fine_plan(profile);
    // Sections just inside the model at its bottom and top, where the planes would touch only.
    const double inset = 1e-4 * profile.grid();
    std::vector<double> heights;
    for (int b : fine.boundaries)
      heights.push_back(std::clamp(profile.z(b), inset, profile.height() - inset));
    // Any gap is closed: a section across a hole in the mesh still has the area it encloses.
    SectionOptions closing;
    closing.max_gap = std::numeric_limits<double>::infinity();
    const std::vector<Section> sections = section_mesh(*request.mesh, heights, closing, request.run);
    std::vector<int> slot(profile.cells() + 1, -1);
    std::vector<double> area(sections.size());
    for (std::size_t s = 0; s < sections.size(); ++s) {
      slot[fine.boundaries[s]] = static_cast<int>(s);
      area[s] = covered_area(sections[s].loops);
    }
    std::unordered_map<std::uint64_t, double> cache;
    auto layer_error = [&](int i, int k) {
      const std::uint64_t key = (std::uint64_t(i) << 32) | std::uint32_t(k);
      auto it = cache.find(key);
      if (it != cache.end()) return it->second;
      const int a = slot[i], b = slot[k];
      const double x =
          std::max(0.0, area[a] + area[b] - 2 * intersection_area(sections[a].loops, sections[b].loops));
      const double e = 0.5 * (profile.z(k) - profile.z(i)) * x;
      cache.emplace(key, e);
      return e;
    };
    const MergeSequence seq(
        fine, profile.max_cells(),
        [&](int i, int j, int k) { return layer_error(i, k) - layer_error(i, j) - layer_error(j, k); },
        loss_of(obj), request.run);
    return read_off(request, seq);
  }
};

}  // namespace

std::unique_ptr<Planner> make_hms() {
  return std::make_unique<HmsPlanner>();
}
std::unique_ptr<Planner> make_ha13() {
  return std::make_unique<Ha13Planner>();
}

}  // namespace salient::core::planners
