// Marlin line framing: comment stripping, "N<n> <cmd>*<xor>" encoding, and checking a framed
// line the way the firmware does. Pure functions: no I/O.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace salient::protocol::marlin {

// XOR of every byte, as Marlin computes it over "N<n> <cmd>" (everything before '*').
std::uint8_t checksum(std::string_view bytes);

// The command without its comment (';' to end of line, or a '(' … ')' block) and without
// surrounding whitespace; empty if nothing is left to send.
std::string strip_comment(std::string_view line);

// The value of a command's word (`X` in "G1 X10 Y2"), as Marlin reads it: absent, or 0 when the
// letter stands without a number ("G28 X").
std::optional<double> word_value(std::string_view command, char letter);

// "N<number> <command>*<checksum>" (no line terminator).
std::string frame(std::uint64_t number, std::string_view command);

// Marlin keeps a line in MAX_CMD_SIZE (96) bytes with its number and checksum: a longer one is cut,
// fails its checksum at every resend and stalls the print. 80 leaves room for "N9999999 " and "*255".
inline constexpr std::size_t kMaxCommandBytes = 80;

// Why `command` (comment stripped) would take over the line numbering the host keeps: a line
// number of its own ("N12 G1 …") or M110. Sent mid-print, M110 N0 makes the firmware ask for
// line 1 again and the host replays the file from there, forever. Empty: it does not.
std::string numbering_command(std::string_view command);

// Why `command` (comment stripped) cannot go over the wire: too long, or a byte that is not
// printable ASCII (NUL, binary, UTF-8), or '*' (it would end the line's checksum), or a numbering
// command (above). Empty: it can.
std::string unsendable(std::string_view command);

struct Unsendable {
  std::size_t line = 0;  // 1-based line of the file
  std::string why;
};
// The first line of a file that cannot be sent, if any.
std::optional<Unsendable> find_unsendable(const std::vector<std::string>& lines);

struct FramedLine {
  std::optional<std::uint64_t> number;  // absent for an unnumbered command
  std::string command;
};

enum class FrameError { none, bad_number, missing_checksum, bad_checksum };

// Parses a received line as the firmware does; `error` says why a numbered line is refused.
FramedLine parse_frame(std::string_view line, FrameError& error);

}  // namespace salient::protocol::marlin
