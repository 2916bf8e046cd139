// MarlinReply: one line from the firmware, classified (pure parsing, no state).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace salient::protocol::marlin {

enum class ReplyKind {
  ok,           // "ok", "ok N12 P15 B3" (ADVANCED_OK), "ok T:…" (temperatures folded in)
  resend,       // "Resend: 12", "rs N12"
  busy,         // "echo:busy: processing" / "busy: paused for user"
  wait,         // "wait" (idle, nothing in the queue)
  start,        // "start": the firmware (re)booted
  error,        // "Error:…"
  temperature,  // an auto-report or M105 line without "ok"
  firmware,     // "FIRMWARE_NAME:…" (M115)
  capability,   // "Cap:AUTOREPORT_TEMP:1"
  action,       // "//action:pause"
  other,        // echo:, comments, anything else
};

struct Temperatures {
  std::optional<double> hotend, hotend_target, bed, bed_target;
};

struct MarlinReply {
  ReplyKind kind = ReplyKind::other;
  std::string text;                              // the line, trimmed
  std::optional<long long> line;                 // resend target, or ADVANCED_OK's N
  std::optional<int> planner_free, buffer_free;  // ADVANCED_OK's P and B
  Temperatures temperatures;                     // when the line carries T:/B:
  std::string name;                              // firmware name, capability name, or host action
  bool enabled = false;                          // capability value
  bool fatal = false;                            // an error after which the firmware halts
};

MarlinReply parse_reply(std::string_view line);

}  // namespace salient::protocol::marlin
