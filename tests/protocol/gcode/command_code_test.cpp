// CommandCode: codes read as Marlin's parser reads them, and which ones move or home the head.
#include "protocol/gcode/command_code.hpp"

#include <doctest/doctest.h>

using namespace salient::protocol;

TEST_CASE("a command's code is read as Marlin reads it") {
  const auto g28 = command_code("G28 X");
  REQUIRE(g28);
  CHECK(g28->letter == 'G');
  CHECK(g28->number == 28);
  CHECK(g28->text == "G28");
  CHECK(command_code("g028")->text == "G28");    // lower case, leading zeros
  CHECK(command_code("G1X10Y5")->text == "G1");  // words glued to the code
  CHECK(command_code("G38.2 Z-10")->text == "G38.2");
  CHECK(command_code("  M104 S200")->number == 104);
  CHECK(command_code("T1")->letter == 'T');
  CHECK(!command_code("X10"));
  CHECK(!command_code("G"));
  CHECK(!command_code(""));
  CHECK(!command_code("N5 G28"));  // a line number first: not a command's code
}

TEST_CASE("moves, homing, probing, set position and motors off are told apart from the rest") {
  for (const char* c : {"G0 X1", "G1 X10 E1", "G2 X1 I1", "G3 X1 J1", "G28", "g28 x", "G29", "G30", "G92 E0",
                        "G38.2 Z-5", "M84", "M18", "G12", "G27", "G425", "M48"}) {
    INFO(c);
    CHECK(moves_or_homes(*command_code(c)));
  }
  for (const char* c : {"M105", "M104 S200", "M106 S255", "M220 S90", "M221 S95", "G4 S1", "M117 hello",
                        "M600", "G90", "G91", "M82", "M114", "T0", "G10", "M112"}) {
    INFO(c);
    CHECK(!moves_or_homes(*command_code(c)));
  }
}
