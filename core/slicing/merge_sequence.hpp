// MergeSequence: greedy merging of adjacent layers in order of a merge cost (the paper's
// initialisation after [HA13], §4), recorded once so the plan at any layer count, or the
// fewest layers within a loss budget, can be read off afterwards.
#pragma once

#include <functional>
#include <vector>

#include "core/common/progress.hpp"
#include "core/slicing/layer_plan.hpp"

namespace salient::core {

class MergeSequence {
 public:
  // Cost of merging layers [i, j) and [j, k) (cells): `order` ranks the merges, `loss` is
  // the change in E the merge causes (SM(i,k) − SM(i,j) − SM(j,k)).
  using Cost = std::function<double(int i, int j, int k)>;

  MergeSequence(const LayerPlan& start, int max_width, const Cost& order, const Cost& loss,
                const RunContext& run = {});

  int most() const { return start_.layer_count(); }
  int fewest() const { return most() - static_cast<int>(removed_.size()); }
  // The plan after merging down to `count` layers (clamped to [fewest, most]).
  LayerPlan at(int count) const;
  // Fewest layers along the sequence whose accumulated loss stays within `budget`.
  int fewest_within(double budget) const;

 private:
  LayerPlan start_;
  std::vector<int> removed_;        // index into start_.boundaries, in merge order
  std::vector<double> loss_after_;  // accumulated loss after each merge
};

}  // namespace salient::core
