// open_printer_connection: the one place a printer's kind becomes a byte link and its protocol a
// link over it. Kind sim starts salient-sim on a pseudo-terminal first (the simulator is its own
// process, not a branch in the link); serial opens the device; tcp connects to the bridge. Every
// byte either way passes the terminal tap.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "protocol/link/printer_link.hpp"
#include "server/config/daemon_config.hpp"
#include "server/printers/sim_process.hpp"

namespace salient::server {

struct TerminalHooks {
  std::function<bool()> wanted;                                // someone watches: split and tell lines
  std::function<void(bool sent, std::string_view line)> line;  // one line, either way
};

struct PrinterConnection {
  std::unique_ptr<protocol::PrinterLink> link;  // not yet handshaken
  std::unique_ptr<SimProcess> sim;              // kind sim: the simulator, stopped when this goes
  std::string device;                           // where it is: a device path or host:port
};

// Throws (std::runtime_error, protocol::LinkError) naming what failed.
PrinterConnection open_printer_connection(const PrinterConfig& config, TerminalHooks terminal);

}  // namespace salient::server
