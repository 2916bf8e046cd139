// G-code thumbnails as PrusaSlicer writes them (libslic3r/GCode/Thumbnails.hpp) and printers'
// screens, OctoPrint's and Moonraker's readers take them: in the header, per image
//   ;
//   ; thumbnail begin WIDTHxHEIGHT LENGTH      (LENGTH: characters of base64)
//   ; <base64, at most 78 characters a line>
//   ; thumbnail end
//   ;
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace salient::core {

struct GcodeThumbnail {
  int width = 0, height = 0;  // pixels
  std::string png;            // the PNG file's bytes
};

// The block above for one thumbnail, each line ending in '\n'.
std::string thumbnail_block(const GcodeThumbnail& thumbnail);

// Every `; thumbnail begin` block of a G-code text, decoded. Throws InputError naming `source` for
// a block that is unterminated, whose length disagrees with its data, or is not valid base64.
std::vector<GcodeThumbnail> read_thumbnails(std::string_view gcode, const std::string& source);

std::string base64_encode(std::string_view bytes);
// Throws InputError naming `source` on a character outside the alphabet or a bad length.
std::string base64_decode(std::string_view text, const std::string& source);

}  // namespace salient::core
