// CancelToken and Progress: how a long core computation is stopped and observed by its caller
// (the daemon's workers, the CLI's progress bar). Core itself starts no threads.
#pragma once

#include <atomic>
#include <functional>
#include <stdexcept>
#include <string_view>

namespace salient::core {

// Set from any thread; checked by the computation at safe points.
class CancelToken {
 public:
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> cancelled_{false};
};

// Thrown out of a computation whose token was cancelled.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

// fraction in [0, 1] of `phase` (a short name such as "plan").
using ProgressFn = std::function<void(std::string_view phase, double fraction)>;

// What a computation is given to report progress and notice cancellation.
struct RunContext {
  const CancelToken* cancel = nullptr;
  ProgressFn progress;

  void check() const {
    if (cancel && cancel->cancelled()) throw Cancelled();
  }
  void report(std::string_view phase, double fraction) const {
    if (progress) progress(phase, fraction);
  }
};

}  // namespace salient::core
