// HostGap: how long the host itself was away between two looks at a printer (ticks, reads). A
// host that was stopped (SIGSTOP, a suspended VM, a thread held up by a frozen database) sent no
// poll and read nothing meanwhile, so that time is not the printer's silence: a node paused for
// 15 s called its idle printer dead. The sessions add it to when they last heard the printer.
#pragma once

#include <chrono>
#include <optional>

namespace salient::protocol {

class HostGap {
 public:
  using Millis = std::chrono::milliseconds;
  // The drivers look every 50-100 ms while they run; a longer gap is the host's absence.
  static constexpr Millis kMaxLookGap{1000};

  // The host looks at `now`: the time it was away since its previous look (zero within kMaxLookGap).
  Millis looked(Millis now) {
    const Millis away = last_ && now - *last_ > kMaxLookGap ? now - *last_ : Millis(0);
    if (!last_ || now > *last_) last_ = now;
    return away;
  }

 private:
  std::optional<Millis> last_;
};

}  // namespace salient::protocol
