// Program: G-code text to the commands a link sends, with where each stands and its layer.
#include "protocol/gcode/program.hpp"

#include <doctest/doctest.h>

#include <memory>

#include "protocol/marlin/marlin_session.hpp"

using salient::protocol::Program;

TEST_CASE("commands without comments or blank lines, with their byte offsets and line numbers") {
  const std::string text = "; header\r\nG28 ; home\r\n\r\n  G1 X1 (inline) Y2\nM105";
  const Program p = Program::parse(text);
  REQUIRE(p.size() == 3);
  CHECK(p[0].text == "G28");
  CHECK(p[0].line == 2);
  CHECK(p[0].offset == 10);
  CHECK(text.substr(p[0].offset, 3) == "G28");
  CHECK(p[1].line == 4);
  CHECK(text.substr(p[1].offset, 7) == "  G1 X1");
  CHECK(p[2].text == "M105");  // the last line needs no newline
  CHECK(p[2].line == 5);
  CHECK(Program::parse("").empty());
  CHECK(Program::parse("; nothing\n\n").empty());
  CHECK(Program::parse("G28\n").size() == 1);
}

TEST_CASE(
    "layers: counted at LAYER_CHANGE comments when the file has them (PrusaSlicer), else at LAYER: (Cura)") {
  const Program prusa = Program::parse(
      "G28\n;LAYER_CHANGE\n;Z:0.2\n;LAYER:0\nG1 Z0.2\nG1 X1\n;LAYER_CHANGE\n;LAYER:1\nG1 Z0.4\n");
  REQUIRE(prusa.size() == 4);
  CHECK(prusa[0].layer == 0);  // before the first layer: counted with it
  CHECK(prusa[1].layer == 0);
  CHECK(prusa[2].layer == 0);
  CHECK(prusa[3].layer == 1);
  CHECK(prusa.layers() == 2);
  const Program cura = Program::parse(";LAYER:0\nG1 Z0.2\n;LAYER:1\nG1 Z0.4\n;LAYER:2\nG1 Z0.6\n");
  CHECK(cura.layers() == 3);
  CHECK(cura[2].layer == 2);
  CHECK(Program::parse("G1 X1\nG1 X2\n").layers() == 1);
  CHECK(Program().layers() == 0);
}

TEST_CASE("lines as a program, and a session reads the program it is given without copying it") {
  const Program p = Program::from_lines({"G28", "; c", "G1 X1"});
  REQUIRE(p.size() == 2);
  CHECK(p[1].line == 3);
  CHECK(p[1].offset == 8);  // "G28\n; c\n"
  auto shared = std::make_shared<const Program>(p);
  salient::protocol::marlin::MarlinSession s;
  s.begin(shared, salient::protocol::marlin::Millis(0));
  CHECK(shared.use_count() == 2);  // the session holds the same program
  CHECK(s.commands_total() == 2);
  CHECK(s.take_output() == "N0 M110 N0*125\n");  // ping-pong: one line until the firmware says more
}
