// Alone in its file: <asm/termbits.h> cannot be included with <termios.h>.
#include "protocol/serial/custom_baud.hpp"

#include <asm/ioctls.h>
#include <asm/termbits.h>
#include <sys/ioctl.h>

#include <cerrno>

namespace salient::protocol::serial {

int set_custom_baud(int fd, unsigned baud) {
  struct termios2 t {};
  if (::ioctl(fd, TCGETS2, &t) != 0) return errno;
  t.c_cflag &= ~static_cast<tcflag_t>(CBAUD);
  t.c_cflag |= BOTHER;
  t.c_ispeed = t.c_ospeed = baud;
  if (::ioctl(fd, TCSETS2, &t) != 0) return errno;
  return 0;
}

}  // namespace salient::protocol::serial
