// translate_gcode against gpx 2.6.8: each expected payload below is what
// `gpx -I -q -m r2x NAME.gcode NAME.x3g` wrote for the G-code in the test (decoded with s3gdump).
#include "protocol/s3g/x3g_translator.hpp"

#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

#include "protocol/s3g/machine.hpp"
#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/x3g_commands.hpp"

using namespace salient::protocol;
using namespace salient::protocol::s3g;

namespace {

Translation translate(const std::vector<std::string>& lines, const std::string& name = "t") {
  TranslateOptions o;
  o.build_name = name;
  return translate_gcode(Program::from_lines(lines), *find_machine("r2x"), o);
}

std::string hex(const std::string& bytes) {
  static const char* d = "0123456789abcdef";
  std::string s;
  for (unsigned char c : bytes) s += {d[c >> 4], d[c & 15]};
  return s;
}

struct Point {
  std::int32_t steps[5];
  std::uint32_t dda_rate;
  std::uint8_t relative;
  float distance;
  std::uint16_t feed_x64;
};

Point point(const std::string& p) {
  REQUIRE(p.size() == 32);
  REQUIRE(static_cast<unsigned char>(p[0]) == 155);
  Point q{};
  std::size_t at = 1;
  for (auto& s : q.steps) s = get_i32(p, at);
  q.dda_rate = get_u32(p, at);
  q.relative = get_u8(p, at);
  q.distance = get_f32(p, at);
  q.feed_x64 = get_u16(p, at);
  return q;
}

}  // namespace

TEST_CASE("the machine table is GPX's r2, r2h and r2x") {
  CHECK(machine_ids() == std::vector<std::string>{"r2", "r2h", "r2x"});
  const Machine& m = *find_machine("r2x");
  CHECK(m.x.steps_per_mm == 88.888889);
  CHECK(m.z.steps_per_mm == 400);
  CHECK(m.a.steps_per_mm == doctest::Approx(96.2752018703));
  CHECK(m.x.max_feedrate == 18000);
  CHECK(m.z.max_feedrate == 1170);
  CHECK(m.x.endstop_max);
  CHECK_FALSE(m.z.endstop_max);
  CHECK(m.extruder_count == 2);
  CHECK_FALSE(find_machine("r2")->a.heats_bed);
  CHECK(find_machine("nope") == nullptr);
}

TEST_CASE("G1: DDA rate, distance and feed clamped per axis, as gpx computes them") {
  // gpx -I -q -m r2x dda.gcode dda.x3g
  const auto t =
      translate({"G92 X0 Y0 Z0 A0 B0", "G1 X10 Y5 F3000", "G1 X10 Y5 Z10 F7200", "G1 X200 Y-60 F30000"});
  REQUIRE(t.program.actions.size() == 6);
  const Point a = point(t.program.actions[1]);
  CHECK(a.steps[0] == 889);
  CHECK(a.steps[1] == 444);
  CHECK(a.dda_rate == 3975);
  CHECK(a.relative == 0x18);
  CHECK(a.distance == doctest::Approx(11.180340));
  CHECK(a.feed_x64 == 3200);
  const Point z = point(t.program.actions[2]);  // F7200 on Z: limited to 1170 mm/min
  CHECK(z.steps[2] == 4000);
  CHECK(z.dda_rate == 7800);
  CHECK(z.feed_x64 == 1248);
  const Point far = point(t.program.actions[3]);  // F30000: limited by X to 18000 along X
  CHECK(far.steps[0] == 17778);
  CHECK(far.steps[1] == -5333);
  CHECK(far.dda_rate == 26666);
  CHECK(far.feed_x64 == 20292);
  CHECK(hex(t.program.actions[3]) == "9b724500002bebffffa00f000000000000000000002a6800001894cf4843444f");
}

TEST_CASE("E: relative, negated steps with the rounding remainder carried") {
  // gpx -I -q -m r2x carry.gcode carry.x3g: 0.013 mm is 1.25 steps
  const auto t = translate({"G92 X0 Y0 Z0 A0 B0", "M83", "G1 E0.013 F1500", "G1 E0.013", "G1 E0.013",
                            "G1 E0.013", "G1 E0.013", "G1 X1 E0.0052"});
  REQUIRE(t.program.actions.size() == 9);
  const std::vector<int> a{-1, -2, -1, -1, -1, -1};
  for (std::size_t i = 0; i < a.size(); ++i) {
    CAPTURE(i);
    CHECK(point(t.program.actions[i + 1]).steps[3] == a[i]);
  }
  CHECK(point(t.program.actions[1]).dda_rate == 1923);
  CHECK(point(t.program.actions[1]).distance == doctest::Approx(0.013));  // |ΔE| for an extruder-only move
  CHECK(point(t.program.actions[6]).dda_rate == 2225);
}

TEST_CASE("homing: 382 µs per step for X and Y at 2500 mm/min, 136 for Z at 1100") {
  // gpx -I -q -m r2x home.gcode home.x3g
  const auto t = translate({"G28", "G162 X Y F2000", "G161 Z"});
  CHECK(hex(t.program.bytes()) ==
        "84037e010000140083048800000014008403dd010000140083048800000014009664009a00");
}

TEST_CASE("G92 is 140 with every axis, rounded to steps") {
  // gpx -I -q -m r2x g92.gcode g92.x3g
  CHECK(hex(translate({"G92 X1.5 Y-2 Z0.3 E4"}).program.actions[0]) ==
        "8c850000004effffff780000008101000000000000");
}

TEST_CASE("M73 starts the build with its name, counts up, and P100 ends it") {
  // gpx -I -q -m r2x m73.gcode m73.x3g: P40 after P50 sends nothing
  const auto t = translate({"M73 P0", "M73 P50", "M73 P40", "M73 P100"}, "m73");
  CHECK(hex(t.program.bytes()) == "99000000006d37330096000086009632009664009a00");
  CHECK(t.program.source == std::vector<std::size_t>{0, 0, 0, 1, 3, 3});
  // A file that never ends its build gets the tail after its last command: gpx -m r2x bare.gcode
  const auto bare = translate({"M104 S230"});
  CHECK(hex(bare.program.bytes()) == "88000302e6009664009a00");
  // The build name is cut at 24 bytes.
  const auto longname = translate({"M136"}, std::string(40, 'n'));
  CHECK(longname.program.actions[0] == std::string("\x99\0\0\0\0", 5) + std::string(24, 'n') + '\0');
}

TEST_CASE("after homing, a move naming only some axes is relative on the others, then 139 absolute") {
  // gpx -I -q -m r2x unknown.gcode unknown.x3g
  const auto t = translate({"G28", "G1 X5 Y5 F1000", "G1 X10 Y10 Z1 F1000"});
  CHECK(hex(t.program.actions[2]) == "9bbc010000bc010000000000000000000000000000160400001c3046e2402a04");
  CHECK(hex(t.program.actions[3]) == "8b7903000079030000900100000000000000000000a2020000");
}

TEST_CASE("unknown commands are skipped with their line, and send nothing") {
  const auto t = translate({"G28", "G29", "M999 S1", "M105", "G4"});
  REQUIRE(t.skipped.size() == 4);
  CHECK(t.skipped[0].line == 2);
  CHECK(t.skipped[0].command == "G29");
  CHECK(t.skipped[1].line == 3);
  CHECK(t.skipped[2].reason.find("query") != std::string::npos);  // gpx would write query 10 into the file
  CHECK(t.skipped[3].reason == "G4 without P (milliseconds)");
  CHECK(t.program.actions.size() == 4);  // 132, 131, and the tail
}

TEST_CASE("arcs (G2/G3) are not s3g: skipped with their line, as gpx skips them") {
  const auto t = translate({"G28", "G2 X10 Y0 I5 J0 E1", "G3 X0 Y0 I-5 J0 E1"});
  REQUIRE(t.skipped.size() == 2);
  CHECK(t.skipped[0].line == 2);
  CHECK(t.skipped[0].reason == "G2 is not an s3g command (gpx skips it too)");
  CHECK(t.skipped[1].command.rfind("G3", 0) == 0);
}

TEST_CASE("M2 ends the program: what follows is reported, not translated") {
  const auto t = translate({"M73 P0", "M2", "G28", "G28"});
  CHECK(t.program.actions.size() == 5);  // 153 150 134, then 150 100 % 154
  REQUIRE(t.skipped.size() == 1);
  CHECK(t.skipped[0].line == 3);
}

TEST_CASE("deliberate fix: G0 without F under G91 keeps its direction") {
  // gpx writes +889 steps for "G0 X-10" here (it takes |Δ| when it makes up G0's feed rate);
  // G1, which gpx gets right, moves -889: so must G0.
  const auto t = translate({"G92 X0 Y0 Z0 A0 B0", "G91", "G0 X-10", "G1 X-10"});
  CHECK(point(t.program.actions[1]).steps[0] == -889);
  CHECK(point(t.program.actions[1]).relative == 0x1F);
  CHECK(t.program.actions[1] == t.program.actions[2]);
}

TEST_CASE("bad G-code never crashes and never yields an unknown action") {
  std::mt19937 rng(7);
  const std::string alphabet = "GMTXYZEFPSRABN0123456789.-+ *;()\t\x01\xff";
  for (int round = 0; round < 300; ++round) {
    std::vector<std::string> lines;
    for (int i = 0; i < 20; ++i) {
      std::string line;
      const int n = static_cast<int>(rng() % 24);
      for (int k = 0; k < n; ++k) line += alphabet[rng() % alphabet.size()];
      lines.push_back(line);
    }
    const auto t = translate(lines);
    CAPTURE(round);
    CHECK_NOTHROW(split_x3g(t.program.bytes()));
    CHECK(split_x3g(t.program.bytes()).size() == t.program.actions.size());
    CHECK(t.program.source.size() == t.program.actions.size());
  }
}

TEST_CASE("build_name_for is gpx's: the base name without its extension") {
  CHECK(build_name_for("/tmp/out/part.x3g") == "part");
  CHECK(build_name_for("part.v2.x3g") == "part.v2");
  CHECK(build_name_for("noext") == "noext");
}

TEST_CASE("M70 takes its message from the comment, which only the file's text still has") {
  const std::string file = "M70 P5 (Hello)\nX5 ; no move for gpx\n";
  const Program p = Program::parse(file);
  TranslateOptions o;
  const auto without = translate_gcode(p, *find_machine("r2x"), o);
  REQUIRE(without.skipped.size() == 1);
  CHECK(without.skipped[0].line == 1);
  o.source = file;
  const auto with = translate_gcode(p, *find_machine("r2x"), o);
  CHECK(with.skipped.empty());
  // gpx -I -q -m r2x: 149 (last of its group, 5 s) "Hello", and nothing for the commented X5
  REQUIRE(with.program.actions.size() == 3);
  CHECK(with.program.actions[0] == std::string("\x95\x02\x00\x00\x05Hello\0", 11));
}

TEST_CASE("without the build's head and tail, as gpx -N ht writes") {
  // gpx -I -q -N ht -m r2x m73.gcode m73.x3g, and -N t on bare.gcode
  TranslateOptions o;
  o.build_start = o.build_end = false;
  const auto t = translate_gcode(Program::from_lines({"M73 P0", "M73 P50", "M73 P40", "M73 P100"}),
                                 *find_machine("r2x"), o);
  CHECK(hex(t.program.bytes()) == "9600008600963200966400");
  const auto bare = translate_gcode(Program::from_lines({"M104 S230"}), *find_machine("r2x"), o);
  CHECK(hex(bare.program.bytes()) == "88000302e600");
}
