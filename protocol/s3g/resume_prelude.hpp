// resume_prelude for s3g: the actions that go before action first_action_of(resume_from) of an
// x3g program so that a board that stopped (a cut link, a reset) carries on where the file left
// it: temperatures set again, the head lifted, homed as the file's own start code homed it,
// heaters waited for, the head back over its last X Y and down to its last Z.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "protocol/s3g/x3g_program.hpp"

namespace salient::protocol::s3g {

// The machine numbers the moves need (defaults: GPX's Replicator 2X, r2x).
struct ResumeMotion {
  double xy_steps_per_mm = 88.888889, z_steps_per_mm = 400;
  double lift_mm = 1;       // above the last layer before travelling
  double z_feed_mm_s = 10;  // r2x's Z is limited to 19.5 mm/s
  double xy_travel_s = 6;   // the XY move's duration: the bed's diagonal at a safe speed
  std::uint16_t heat_timeout_s = 3600;
  bool rehome = true;  // replay the file's homing (131/132/140/144 before its first move)
};

// Payloads (each a whole action, ready for S3gSession::begin's prelude). Empty when resume_from
// is 0. A position is restored only when a queue point (139/142/155) precedes the resume point.
std::vector<std::string> resume_prelude(const X3gProgram& program, std::size_t resume_from,
                                        const ResumeMotion& motion = {});

}  // namespace salient::protocol::s3g
