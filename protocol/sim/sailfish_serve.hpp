// salient-sim --firmware sailfish: the simulated Sailfish board served on a pseudo-terminal.
#pragma once

#include <csignal>
#include <string>

#include "protocol/sim/sailfish_firmware.hpp"

namespace salient::protocol::sim {

struct SailfishServeOptions {
  SailfishConfig config;
  std::string faults, log_path, link_path, stats_path;
};

// Prints the device path (and links it to link_path), then serves until *stop is set. The log
// gets one line per executed action, its payload in lowercase hex; the stats file one JSON
// object on exit. Throws std::invalid_argument for a bad fault spec, std::runtime_error when a
// file cannot be written.
int serve_sailfish(SailfishServeOptions& o, const volatile std::sig_atomic_t* stop);

}  // namespace salient::protocol::sim
