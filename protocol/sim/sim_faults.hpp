// SimFaults: what goes wrong on the simulated printer, from a spec such as
// "noise=0.02,drop-ok=0.01,resend-without-ok,disconnect-after=5000,reset-after=9000,thermal-runaway-at=12000".
#pragma once

#include <cstdint>
#include <string_view>

namespace salient::protocol::sim {

struct SimFaults {
  double noise = 0;                 // chance that a received line has one byte corrupted
  double drop_ok = 0;               // chance that an ok is never sent
  bool resend_without_ok = false;   // "Resend: N" without the ok that Marlin sends after it
  long long disconnect_after = 0;   // executed commands, then the cable is pulled; 0: never
  long long reset_after = 0;        // executed commands, then the board reboots ("start")
  long long thermal_runaway_at = 0; // executed commands, then thermal runaway: kill()
  std::uint64_t seed = 1;           // the faults are random but repeatable
};

// Throws std::invalid_argument naming the field that is wrong.
SimFaults parse_faults(std::string_view spec);

}  // namespace salient::protocol::sim
