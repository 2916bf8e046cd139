#include "protocol/sim/pseudo_terminal.hpp"

#include <fcntl.h>
#include <sys/inotify.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <system_error>

namespace salient::protocol::sim {
namespace {

[[noreturn]] void fail(const char* what) {
  throw std::system_error(errno, std::generic_category(), what);
}

}  // namespace

PseudoTerminal::PseudoTerminal() {
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (master_ < 0) fail("posix_openpt");
  if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0) fail("grantpt/unlockpt");
  char name[128];
  if (::ptsname_r(master_, name, sizeof name) != 0) fail("ptsname");
  path_ = name;
  slave_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_ < 0) fail("open pseudo-terminal");
  termios t{};
  if (::tcgetattr(slave_, &t) != 0) fail("tcgetattr");
  ::cfmakeraw(&t);  // no echo, no line editing, no CR/LF translation: bytes as a UART sees them
  if (::tcsetattr(slave_, TCSANOW, &t) != 0) fail("tcsetattr");
}

PseudoTerminal::~PseudoTerminal() {
  close();
}

std::string PseudoTerminal::read_available() {
  std::string out;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n > 0) {
      out.append(buf, static_cast<std::size_t>(n));
      if (static_cast<std::size_t>(n) < sizeof buf) return out;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EIO)) return out;  // EIO: no host yet
    if (n == 0) return out;
    fail("read pseudo-terminal");
  }
}

std::size_t PseudoTerminal::write_some(std::string_view bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    fail("write pseudo-terminal");
  }
  return done;
}

void PseudoTerminal::discard_output() {
  // Our end writes to the master; what the host has yet to read waits on the slave side.
  if (::tcflush(slave_, TCIFLUSH) != 0) fail("tcflush pseudo-terminal");
}

void PseudoTerminal::watch_opens() {
  watch_ = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (watch_ < 0) fail("inotify_init1");
  // Our own descriptor on the slave was opened before this: only the host's opens count.
  if (::inotify_add_watch(watch_, path_.c_str(), IN_OPEN) < 0)
    fail("inotify_add_watch on the pseudo-terminal");
}

int PseudoTerminal::take_opens() {
  int opens = 0;
  alignas(inotify_event) char buf[4096];
  for (;;) {
    const ssize_t n = ::read(watch_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return opens;  // EAGAIN: none left
    for (ssize_t at = 0; at < n;) {
      const auto* e = reinterpret_cast<const inotify_event*>(buf + at);
      if (e->mask & IN_OPEN) ++opens;
      at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
    }
  }
}

void PseudoTerminal::close() {
  if (watch_ >= 0) ::close(watch_);
  if (slave_ >= 0) ::close(slave_);
  if (master_ >= 0) ::close(master_);
  watch_ = slave_ = master_ = -1;
}

}  // namespace salient::protocol::sim
