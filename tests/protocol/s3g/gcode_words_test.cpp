#include "protocol/s3g/gcode_words.hpp"

#include <doctest/doctest.h>

using namespace salient::protocol::s3g;

TEST_CASE("words are read as gpx reads them") {
  const GcodeWords w = parse_gcode_words("N12 G1 X 1 0.5 Y-.5 E+2 F1200.");
  CHECK(w.flag == (word::G | word::X | word::Y | word::E | word::F));
  CHECK(w.g == 1);
  CHECK(w.x == 10.5);  // blanks between digits are dropped, as normalize_word drops them
  CHECK(w.y == -0.5);
  CHECK(w.e == 2);
  CHECK(w.f == 1200);
}

TEST_CASE("reading stops at a checksum or at a character that starts no word") {
  CHECK(parse_gcode_words("G1 X5*71 Y3").flag == (word::G | word::X));
  const GcodeWords w = parse_gcode_words("G1 X1.2.3 Y4");
  CHECK(w.x == 1.2);
  CHECK((w.flag & word::Y) == 0u);
}

TEST_CASE("a letter without digits is present with value 0, and unknown letters are passed over") {
  const GcodeWords w = parse_gcode_words("G28 X Q7 Y");
  CHECK(w.flag == (word::G | word::X | word::Y));
  CHECK(w.x == 0);
  CHECK(parse_gcode_words("M862.3 P").m == 862);
  CHECK(parse_gcode_words("G99999999999999999999").g == -1);  // atoi of a saturated strtol
  CHECK(parse_gcode_words("T-1").t == -1);
}
