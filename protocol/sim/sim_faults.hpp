// SimFaults: what goes wrong on the simulated printer, from a spec such as
// "noise=0.02,drop-ok=0.01,resend-without-ok,disconnect-after=5000,reset-after=9000,thermal-runaway-at=12000".
//
// Two kinds. Random faults (noise, drop-ok) come from a seeded generator, so a seed repeats a run.
// Faults at a known moment, after OctoPrint's virtual printer (dont_answer, go_awol, rerequest_last),
// name a command: commands are counted from power-on as the firmware takes them in, the host's M115
// and M110 included, so "command N" is the N-th line of the --log. Each fires once. Seconds are
// wall-clock seconds whatever --time-scale, since they are aimed at the host's timeouts:
// - silent-after=N: after command N's ok the board hangs, as one that locked up: it says nothing
//   (no ok, no busy, no temperatures), and what the host sends is read and lost. The port stays
//   open. silent-for=S: it comes back after S seconds (a stall), with what it held before.
// - rerequest=N: command N arrives intact but is refused as if corrupted, "Resend: N" + "ok" as
//   Marlin's flush_and_request_resend says it; the host must send it again, and it runs once.
//   An unnumbered line cannot be asked for again, so the first numbered one from N on is taken.
// - busy-for=S: the first command that waits (G4, G28, M400, M109, M190), or command N with
//   busy-at=N, is held S seconds before it runs, saying "echo:busy: processing" every 2 s.
// - malformed-ok=N: command N's ok arrives as "o\0…": its 'k' is a NUL, as a framing error reads
//   on most UARTs; no host can take it for an ok, even one that drops NULs or non-ASCII bytes.
// - reset-on-open: the board reboots whenever the host opens the port, as an Arduino does on DTR:
//   what it held and had not yet sent is lost, for boot-for=S seconds (its bootloader, 0.5 by
//   default) what arrives is lost too, then it says "start" and its banner.
#pragma once

#include <cstdint>
#include <string_view>

namespace salient::protocol::sim {

struct SimFaults {
  double noise = 0;                  // chance that a received line has one byte corrupted
  double drop_ok = 0;                // chance that an ok is never sent
  bool resend_without_ok = false;    // "Resend: N" without the ok that Marlin sends after it
  long long disconnect_after = 0;    // executed commands, then the cable is pulled; 0: never
  long long reset_after = 0;         // executed commands, then the board reboots ("start")
  long long thermal_runaway_at = 0;  // executed commands, then thermal runaway: kill()
  long long silent_after = 0;        // executed commands, then the board hangs; 0: never
  double silent_for = 0;             // seconds the hang lasts; 0: for ever
  long long rerequest = 0;           // this command is asked for again though intact; 0: never
  double busy_for = 0;               // seconds a command is held with busy keepalives; 0: never
  long long busy_at = 0;             // the command held; 0: the first that waits
  long long malformed_ok = 0;        // this command's ok arrives garbled; 0: never
  bool reset_on_open = false;        // the board reboots when the host opens the port
  double boot_for = 0.5;             // with reset_on_open: seconds deaf before "start"
  std::uint64_t seed = 1;            // the faults are random but repeatable
};

// Throws std::invalid_argument naming the field that is wrong.
SimFaults parse_faults(std::string_view spec);

// Every fault, one a line, for salient-sim --help.
std::string_view faults_help();

}  // namespace salient::protocol::sim
