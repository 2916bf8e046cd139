// CancelToken and Progress: how a long core computation is stopped and observed by its caller
// (the daemon's workers, the CLI's progress bar). Core itself starts no threads.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string_view>

namespace salient::core {

// Set from any thread; checked by the computation at safe points. A deadline (a job's time
// limit) cancels it too, at the first check after it passes: no watchdog thread needed.
class CancelToken {
 public:
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed) || expired(); }
  void expire_after(std::chrono::steady_clock::duration limit) {
    deadline_.store((std::chrono::steady_clock::now() + limit).time_since_epoch().count(),
                    std::memory_order_relaxed);
  }
  // cancel() was called (a person's cancel, a lost claim), whatever the deadline.
  bool cancel_called() const { return cancelled_.load(std::memory_order_relaxed); }
  // Past the deadline (whether or not cancel() was also called).
  bool expired() const {
    const auto d = deadline_.load(std::memory_order_relaxed);
    return d != 0 && std::chrono::steady_clock::now().time_since_epoch().count() >= d;
  }

 private:
  std::atomic<bool> cancelled_{false};
  std::atomic<std::chrono::steady_clock::rep> deadline_{0};  // 0: none
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
