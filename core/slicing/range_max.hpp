// RangeMax: a sparse table answering max over [i, j) in O(1) after O(n log n) preparation.
#pragma once

#include <algorithm>
#include <bit>
#include <vector>

namespace salient::core {

class RangeMax {
 public:
  RangeMax() = default;
  explicit RangeMax(const std::vector<float>& values) {
    const std::size_t n = values.size();
    table_.push_back(values);
    for (std::size_t span = 1; 2 * span <= n; span *= 2) {
      const std::vector<float>& prev = table_.back();
      std::vector<float> next(n - 2 * span + 1);
      for (std::size_t i = 0; i < next.size(); ++i) next[i] = std::max(prev[i], prev[i + span]);
      table_.push_back(std::move(next));
    }
  }

  // Max of values[i..j-1]; requires i < j.
  float operator()(std::size_t i, std::size_t j) const {
    const std::size_t level = std::bit_width(j - i) - 1;
    return std::max(table_[level][i], table_[level][j - (std::size_t{1} << level)]);
  }

 private:
  std::vector<std::vector<float>> table_;
};

}  // namespace salient::core
