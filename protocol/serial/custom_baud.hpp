// Line speeds that termios has no constant for (250000, 500000 on some adapters): Linux termios2.
#pragma once

namespace salient::protocol::serial {

// Returns 0 or an errno value.
int set_custom_baud(int fd, unsigned baud);

}  // namespace salient::protocol::serial
