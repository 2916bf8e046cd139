// Marlin line framing: checksums as the firmware computes them, comment stripping, parsing.
#include "protocol/marlin/line_codec.hpp"

#include <doctest/doctest.h>

using namespace salient::protocol::marlin;

TEST_CASE("framing matches Marlin's documented example") {
  // Marlin's docs: "N123 M104 S200*" has checksum 4... computed here independently by XOR.
  std::uint8_t x = 0;
  for (char c : std::string("N1 G28")) x ^= static_cast<std::uint8_t>(c);
  CHECK(frame(1, "G28") == "N1 G28*" + std::to_string(x));
  CHECK(frame(0, "M110 N0") == "N0 M110 N0*" + std::to_string(checksum("N0 M110 N0")));
}

TEST_CASE("comments are stripped") {
  CHECK(strip_comment("G1 X10 Y20 ; move") == "G1 X10 Y20");
  CHECK(strip_comment("G1 (inline) X1") == "G1  X1");
  CHECK(strip_comment("; only a comment") == "");
  CHECK(strip_comment("  M105\r\n") == "M105");
}

TEST_CASE("parse accepts good frames and refuses bad ones") {
  FrameError e;
  FramedLine l = parse_frame(frame(42, "G1 X1"), e);
  CHECK(e == FrameError::none);
  CHECK(l.number == 42u);
  CHECK(l.command == "G1 X1");
  std::string bad = frame(42, "G1 X1");
  bad[5] = '2';
  parse_frame(bad, e);
  CHECK(e == FrameError::bad_checksum);
  parse_frame("N5 G28", e);
  CHECK(e == FrameError::missing_checksum);
  l = parse_frame("M105", e);
  CHECK(e == FrameError::none);
  CHECK_FALSE(l.number.has_value());
}

TEST_CASE("line numbers and M110 belong to the host: refused, with the reason") {
  // Sent mid-print, "M110 N0" made the firmware ask for line 1 and the host replay the file forever.
  for (const char* c : {"M110 N0", "M110", "m110 N5", "M0110 N0", "N12 G1 X5", "N-1 M105", "n3 M105"}) {
    INFO(c);
    CHECK(!numbering_command(c).empty());
    CHECK(unsendable(c) == numbering_command(c));
  }
  CHECK(numbering_command("M110 N0").find("M110") != std::string::npos);
  CHECK(numbering_command("N12 G1 X5").find("N12") != std::string::npos);
  for (const char* c : {"M1100", "M11", "G1 X10 ; N5", "M117 N12 done", "G28", "M105", "N"}) {
    INFO(c);
    CHECK(numbering_command(c).empty());
  }
}
