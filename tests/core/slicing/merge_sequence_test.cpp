// MergeSequence: merges respect the maximum width at every count, in order of cost.
#include "core/slicing/merge_sequence.hpp"

#include <doctest/doctest.h>

using namespace salient::core;

TEST_CASE("no plan along the sequence has a layer wider than the maximum") {
  // Regression: a merge re-queued when it had become too wide left its older, still-valid
  // queue entry live, so layers of 60+ cells appeared with a maximum of 40.
  LayerPlan start;
  for (int i = 0; i <= 20; ++i) start.boundaries.push_back(i * 10);
  const auto cost = [](int i, int j, int k) { return double((k - i) * (k - i)) + 0.001 * j; };
  const MergeSequence seq(start, 40, cost, cost);
  CHECK(seq.fewest() == 5);
  for (int count = seq.most(); count >= seq.fewest(); --count) {
    const LayerPlan p = seq.at(count);
    CHECK(p.layer_count() == count);
    for (int i = 0; i < p.layer_count(); ++i) CHECK(p.width(i) <= 40);
  }
}

TEST_CASE("cheapest merges come first and the loss budget is read off exactly") {
  LayerPlan start{{0, 10, 20, 30, 40}};
  // merging at boundary 20 is free, at 10 costs 1, at 30 costs 2
  const auto cost = [](int, int j, int) { return j == 20 ? 0.0 : j == 10 ? 1.0 : 2.0; };
  const MergeSequence seq(start, 100, cost, cost);
  CHECK(seq.at(3) == LayerPlan{{0, 10, 30, 40}});
  CHECK(seq.fewest_within(0.0) == 3);
  CHECK(seq.fewest_within(1.0) == 2);
  CHECK(seq.fewest_within(10.0) == 1);
}
