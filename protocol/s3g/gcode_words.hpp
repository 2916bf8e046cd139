// GcodeWords: one G-code command's words, read exactly as GPX 2.6.8 reads a line (gpx.c
// normalize_word and gpx_convert_line), so that the translator sees the numbers gpx sees.
#pragma once

#include <string>
#include <string_view>

namespace salient::protocol::s3g {

// Which words a command has, numbered as gpx.h numbers them; the axis bits are s3g's axis bits.
namespace word {
inline constexpr unsigned X = 0x1, Y = 0x2, Z = 0x4, A = 0x8, B = 0x10, XYZ = 0x7, AXES = 0x1F;
inline constexpr unsigned E = 0x20, F = 0x40, P = 0x100, R = 0x400, S = 0x800, G = 0x1000, M = 0x2000,
                          T = 0x4000, COMMENT = 0x8000;
}  // namespace word

struct GcodeWords {
  unsigned flag = 0;  // word:: bits of the words present
  double x = 0, y = 0, z = 0, a = 0, b = 0, e = 0, f = 0, p = 0, r = 0, s = 0;
  int g = 0, m = 0, t = 0;
  std::string comment;  // the last ";…" or "(…)" on the line, trimmed (M70's message)
};

// A letter, blanks, an optional sign, digits and one '.' with blanks allowed between the digits;
// the value is what those characters spell (G, M, T: its integer part). A leading N (line number)
// is dropped; comments are read as gpx reads them (a ";@"/"(@" macro ends the line); reading stops
// at '*' (checksum) or any other character that starts no word, as gpx stops there; letters gpx
// does not use are read and ignored.
GcodeWords parse_gcode_words(std::string_view command);

}  // namespace salient::protocol::s3g
