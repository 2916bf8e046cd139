// SailfishFaults: what goes wrong on the simulated Sailfish board, from a spec such as
// "noise=0.02,reply-noise=0.02,drop-reply=0.01,full-storm=0.01,reset-at=9000,seed=7".
//
// Random faults come from a seeded generator, so a seed repeats a run. Faults at a known moment
// count executed actions from power-on, as the --log does: "action N" is line N of the log. Each
// fires once, as action N starts.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace salient::protocol::sim {

// noise hits the start byte or the length of 2 packets in 35: the board then reads the rest as
// stray bytes (80 each) and may open a "packet" at a D5 inside them, which swallows a resend sent
// at once, the same way each time. A host that saw 80s waits out the 200 ms packet timeout.
struct SailfishFaults {
  double noise = 0;               // chance that a received packet has one byte corrupted
  double reply_noise = 0;         // chance that a reply has one byte corrupted on the way back
  double drop_reply = 0;          // chance that a packet is acted on and its reply lost
  double full_storm = 0;          // chance that an action that fits starts a burst of refusals (82)
  long long reset_at = 0;         // after this action the board resets; 0: never
  long long cancel_at = 0;        // after this action the user cancels on the LCD (89); 0: never
  long long heater_fault_at = 0;  // after this action the heaters shut down (8B); 0: never
  long long silent_after = 0;     // after this action the board hangs for ever; 0: never
  std::uint64_t seed = 1;
};

// Throws std::invalid_argument naming the field that is wrong.
SailfishFaults parse_sailfish_faults(std::string_view spec);

// Every fault, one a line, for salient-sim --help.
std::string_view sailfish_faults_help();

}  // namespace salient::protocol::sim
