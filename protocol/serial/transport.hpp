// Transport: a byte link to a printer (USB serial, or TCP to a ser2net-style bridge), used by one
// thread at a time. No Asio in this header: the implementations live in their .cpp files.
#pragma once

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "protocol/link/printer_link.hpp"

namespace salient::protocol::serial {

using protocol::LinkError;  // thrown when the link is gone or cannot be opened

class Transport {
 public:
  virtual ~Transport() = default;
  virtual void write(std::string_view bytes) = 0;  // all of it, or LinkError
  // Waits up to `timeout` for bytes and returns those that came (empty: none); LinkError when
  // the link is gone.
  virtual std::string read(std::chrono::microseconds timeout) = 0;
  virtual void discard_input() = 0;  // stale bytes from before we were listening
  virtual std::string describe() const = 0;
};

struct SerialOptions {
  std::string device;
  unsigned baud = 250000;   // any rate: non-standard ones (250000) go through termios2
  bool low_latency = true;  // ASYNC_LOW_LATENCY on FTDI-style adapters (ignored where unsupported)
  bool reset = false;       // pulse DTR: boards with auto-reset reboot ("start")
};

std::unique_ptr<Transport> open_serial(const SerialOptions& options);
// "host:port"; throws LinkError naming what failed.
std::unique_ptr<Transport> open_tcp(const std::string& host_port);

}  // namespace salient::protocol::serial
