// MergeSequence: a priority queue of candidate merges over a linked list of boundaries, with
// stale entries recognised by a per-boundary version stamp.
#include "core/slicing/merge_sequence.hpp"

#include <algorithm>
#include <queue>

namespace salient::core {
namespace {

struct Candidate {
  double cost;
  int boundary;  // index into the start plan's boundaries
  unsigned stamp;
  bool operator>(const Candidate& o) const {
    return cost > o.cost || (cost == o.cost && boundary > o.boundary);
  }
};

}  // namespace

MergeSequence::MergeSequence(const LayerPlan& start, int max_width, const Cost& order, const Cost& loss,
                             const RunContext& run)
    : start_(start) {
  const std::vector<int>& b = start.boundaries;
  const int n = static_cast<int>(b.size());
  std::vector<int> prev(n), next(n);
  std::vector<unsigned> stamp(n, 0);
  for (int i = 0; i < n; ++i) {
    prev[i] = i - 1;
    next[i] = i + 1;
  }
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;
  auto push = [&](int i) {
    if (i <= 0 || i >= n - 1) return;
    ++stamp[i];  // whatever was queued for i before is stale now
    const int a = b[prev[i]], m = b[i], c = b[next[i]];
    if (c - a > max_width) return;  // widths only grow: this merge never becomes valid
    queue.push({order(a, m, c), i, stamp[i]});
  };
  for (int i = 1; i < n - 1; ++i) push(i);
  double total = 0;
  while (!queue.empty()) {
    const Candidate top = queue.top();
    queue.pop();
    if (top.stamp != stamp[top.boundary]) continue;
    if (removed_.size() % 64 == 0) run.check();
    const int i = top.boundary;
    total += loss(b[prev[i]], b[i], b[next[i]]);
    removed_.push_back(i);
    loss_after_.push_back(total);
    ++stamp[i];  // retire
    next[prev[i]] = next[i];
    prev[next[i]] = prev[i];
    push(prev[i]);
    push(next[i]);
  }
}

LayerPlan MergeSequence::at(int count) const {
  count = std::clamp(count, fewest(), most());
  std::vector<bool> gone(start_.boundaries.size(), false);
  for (int t = 0; t < most() - count; ++t) gone[removed_[t]] = true;
  LayerPlan plan;
  for (std::size_t i = 0; i < gone.size(); ++i)
    if (!gone[i]) plan.boundaries.push_back(start_.boundaries[i]);
  return plan;
}

int MergeSequence::fewest_within(double budget) const {
  // Losses are non-negative for the metrics we use, so the accumulated loss only grows.
  const double slack = 1e-12 * std::max(1.0, std::abs(budget));
  int merges = 0;
  while (merges < static_cast<int>(removed_.size()) && loss_after_[merges] <= budget + slack) ++merges;
  return most() - merges;
}

}  // namespace salient::core
