// A serial printer unplugged and plugged in again: while it has no link and should have one, the
// printer's thread looks at its device path every kReplugPoll. Named by a stable path
// (/dev/serial/by-id/…, or a udev symlink), the device comes back under the same name even when
// the kernel gives it another ttyACM number. Polling a path is simpler than inotify on
// /dev/serial/by-id (which exists only while some device is plugged in) and 2 s is well inside
// the time a person takes to look.
#include <sys/stat.h>

#include "server/printers/printer.hpp"

namespace salient::server {

void Printer::poll_replug(Replug& r) {
  using Clock = std::chrono::steady_clock;
  struct stat st {};
  const bool present = ::stat(config_.port.c_str(), &st) == 0;  // follows symlinks: a dangling one is absent
  if (!present) {
    if (r.present)
      set_state(PrinterState::error,
                config_.port + " is gone (unplugged?): connecting again when it comes back");
    r.present = false;
    return;
  }
  const bool back = !r.present;
  r.present = true;
  // A device that is there but did not answer is tried again now and then, not every poll: each
  // try resets most boards (DTR) and shows as a connecting state.
  if (!back && Clock::now() - r.last_try < std::chrono::seconds(10)) return;
  r.last_try = Clock::now();
  open_link();
}

}  // namespace salient::server
