// A serial printer unplugged and plugged in again: while it has no link and should have one, the
// printer's thread looks at its device path every kReplugPoll. Named by a stable path
// (/dev/serial/by-id/…, or a udev symlink), the device comes back under the same name even when
// the kernel gives it another ttyACM number. Polling a path is simpler than inotify on
// /dev/serial/by-id (which exists only while some device is plugged in) and 2 s is well inside
// the time a person takes to look.
#include <sys/stat.h>

#include "server/printers/printer.hpp"

namespace salient::server {

namespace {

// A device node's identity: a replug makes a new node (a new inode and change time), even when
// the kernel gives it the old name and number, so a quick replug is told from a silent board.
std::string identity(const struct stat& st) {
  return std::to_string(st.st_rdev) + ":" + std::to_string(st.st_ino) + ":" +
         std::to_string(st.st_ctim.tv_sec) + "." + std::to_string(st.st_ctim.tv_nsec);
}

}  // namespace

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
  const bool back = !r.present || identity(st) != r.tried;  // gone and back, or replaced between two looks
  r.present = true;
  // The same device that did not answer is tried again now and then, not every poll: each try
  // resets most boards (DTR) and shows as a connecting state.
  if (!back && Clock::now() - r.last_try < std::chrono::seconds(10)) return;
  r.last_try = Clock::now();
  r.tried = identity(st);
  open_link();
}

}  // namespace salient::server
