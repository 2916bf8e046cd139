// Marlin line framing: comment stripping, "N<n> <cmd>*<xor>" encoding, and checking a framed
// line the way the firmware does. Pure functions: no I/O.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace salient::protocol::marlin {

// XOR of every byte, as Marlin computes it over "N<n> <cmd>" (everything before '*').
std::uint8_t checksum(std::string_view bytes);

// The command without its comment (';' to end of line, or a '(' … ')' block) and without
// surrounding whitespace; empty if nothing is left to send.
std::string strip_comment(std::string_view line);

// "N<number> <command>*<checksum>" (no line terminator).
std::string frame(std::uint64_t number, std::string_view command);

struct FramedLine {
  std::optional<std::uint64_t> number;  // absent for an unnumbered command
  std::string command;
};

enum class FrameError { none, bad_number, missing_checksum, bad_checksum };

// Parses a received line as the firmware does; `error` says why a numbered line is refused.
FramedLine parse_frame(std::string_view line, FrameError& error);

}  // namespace salient::protocol::marlin
