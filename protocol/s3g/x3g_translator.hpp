// translate_gcode: G-code → s3g actions, byte for byte what GPX 2.6.8 writes with
// `gpx -I -q -m <machine> in.gcode NAME.x3g` for the commands listed below. It lives in protocol/
// because it is the protocol's own vocabulary (steps per mm, DDA rates, packet layouts) and knows
// nothing of meshes or plans: core/ stays about planning and slicing and writes G-code; this turns
// G-code into what a Replicator executes, for an .x3g file or for the s3g link to stream.
//
// GPX's arithmetic, kept exactly (the x3g is compared byte for byte against Debian's gpx):
// - XYZ steps are absolute, round(mm × steps/mm); A/B are relative and negated:
//   −round(ΔE × steps/mm + the carried rounding remainder); homing and M132 zero the remainder.
// - 155's feed rate is F × M220 %, limited per axis to its maximum (in X, Y, Z, A, B order, each
//   against the ratio of that axis to the XYZ length); minutes = XYZ length / feed (|ΔE| when the
//   XYZ length is 0); usec = 60000000.0L × minutes and dda_rate = 1e6L / (usec / the largest
//   step count), both through long double and stored as double, as gpx.c computes them.
// - A position is unknown after homing or M132 until a G92 or an absolute move names it; a move
//   on an axis that is unknown becomes 139 (absolute, unaccelerated) when it names every unknown
//   axis, else a 155 with the unknown axes relative (GPX's fix of markwal/GPX#1); G91 → mask 0x1F.
// - The first M73 P<100 (or M136) starts the build: 153 with the build name, 150 0 %, 134 to the
//   current tool; M73 P100 (or M137, M2) ends it with 150 100 % and 154; a file that never ends it
//   gets them after its last command (also when it never started: GPX's "ready" counts as running).
//
// Covered: G0 G1 G4 G10 G15 G21 G28 G53–G59 G71 G90 G91 G92 G130 G161 G162, M0 M2 M6 M17 M18 M22
// M26 M30 M31 M70 M71 M72 M73 M82 M83 M84 M101–M104 M106–M112 M116 M126 M127 M131–M137 M140 M190 M220
// M221 M300 M320 M321 M400, T<n>. Anything else is reported in `skipped` with its line and sends
// nothing, as gpx (which warns and sends nothing) does; never an unknown action, which would stall
// the board. Not covered (reported when met): GPX's macros (";@…"), ini files and EEPROM, M108 R
// (simulated RPM), M322, M420; M70/M71 (messages) need options.source.
//
// Words are read as gpx reads them (gcode_words.hpp), from the whole line when options.source is
// given; without it, comments are gone: M70/M71 are skipped and "X5 ; note" (ignored by gpx) moves.
//
// Deliberate differences from gpx (docs/x3g.md):
// - G0 without F under G91 keeps its direction: gpx, making up G0's feed rate, takes the absolute
//   value of the deltas, which under G91 are the move itself ("G91", "G0 X-10" goes to +10 mm).
// - Host queries (M1 pause, M20/M21/M23–M25/M27–M29 SD card, M105, M114, M115) are skipped: gpx
//   writes their query packets into the .x3g file, where they are not actions and would stall or
//   confuse a board playing the file.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/gcode/program.hpp"
#include "protocol/s3g/machine.hpp"
#include "protocol/s3g/x3g_program.hpp"

namespace salient::protocol::s3g {

struct TranslateOptions {
  // 153's build name (cut at 24 bytes), as gpx takes it from the output file's base name without
  // its extension ("part.x3g" → "part"); build_name_for() does that.
  std::string build_name = "GPX 2.6.8";
  bool build_start = true;  // 153 when the build starts (gpx -N h turns it off)
  bool build_end = true;    // 150 100 % and 154 at the end of the file (gpx -N t turns it off)
  // The text the Program was parsed from, when the caller has it: each command is then read from
  // its whole line (Program::Command::offset), comments included, as gpx reads it — M70/M71 take
  // their message from the comment, and a line of bare axis words with a comment is no move.
  std::string_view source;
};

// A command that sent nothing because the translator does not handle it.
struct Skipped {
  std::size_t line = 0;  // 1-based, in the G-code file
  std::string command, reason;
};

struct Translation {
  X3gProgram program;  // source[i]: the index of the Program command action i came from
  std::vector<Skipped> skipped;
};

// The whole program, in order. Never throws on bad G-code: what it cannot translate is skipped.
Translation translate_gcode(const Program& gcode, const Machine& machine, const TranslateOptions& options);

// gpx's build name for an output path: the base name, cut at its last '.'.
std::string build_name_for(const std::string& output_path);

}  // namespace salient::protocol::s3g
