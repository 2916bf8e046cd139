#include "protocol/marlin/resume_prelude.hpp"

#include <doctest/doctest.h>

using salient::protocol::marlin::resume_prelude;

TEST_CASE("the resume prelude restores temperatures, modes, fan, position, re-primes, then the extruder") {
  const std::vector<std::string> gcode = {"; header",
                                          "M140 S60",
                                          "M104 S210",
                                          "G28 ; home",
                                          "M190 S60",
                                          "M109 S215",
                                          "G90",
                                          "M83",
                                          "",
                                          "G1 Z0.3 F600",
                                          "G1 X10 Y20 E1.5 F1800",
                                          "M106 S128",
                                          "G1 X12.5 Y20 E0.2",
                                          "G1 X13 Y21 E0.2 F1200"};
  // Eleven commands done: the last one was "G1 X12.5 Y20 E0.2".
  const auto p = resume_prelude(salient::protocol::Program::from_lines(gcode), 11);
  CHECK(p == std::vector<std::string>{"M140 S60", "M104 S215", "M190 S60", "M109 S215", "G21", "G90", "M83",
                                      "M106 S128", "G1 Z1.3 F600", "G1 X12.5 Y20 F6000", "G92 E0",
                                      "G1 E1 F300", "G92 E1.7", "G1 Z0.3 F600", "G1 F1800"});
}

TEST_CASE("nothing done yet: no heat, the head at home") {
  const auto p = resume_prelude(salient::protocol::Program::from_lines({"G1 X5 F100"}), 0);
  CHECK(p.front() == "G21");
  CHECK(p.back() == "G1 Z0 F600");
}
