// G-code parsing and the time estimate against closed-form trapezoids.
#include "core/gcode/time_estimator.hpp"

#include <doctest/doctest.h>

#include <cmath>

#include "core/common/input_error.hpp"
#include "core/gcode/gcode_line.hpp"

using namespace salient::core;

namespace {

// Time of one move of length L from rest to rest-within-jerk: accelerate at a from v0 to v,
// cruise, decelerate to v0 (v0 = the jerk speed along X).
double trapezoid(double L, double v, double a, double v0) {
  const double d = (v * v - v0 * v0) / (2 * a);
  if (2 * d <= L) return 2 * (v - v0) / a + (L - 2 * d) / v;
  const double peak = std::sqrt(a * L + v0 * v0);
  return 2 * (peak - v0) / a;
}

MachineLimits limits(double accel, double jerk) {
  MachineLimits m;
  m.acceleration = m.travel_acceleration = m.retract_acceleration = accel;
  for (double& j : m.jerk) j = jerk;
  return m;
}

}  // namespace

TEST_CASE("G-code words, comments, line numbers and checksums") {
  GcodeError e;
  GcodeLine g = parse_gcode_line("N12 G1 X10.5 Y-3 E.25 F1800*71 ; move", e);
  CHECK(e == GcodeError::none);
  CHECK(g.is('G', 1));
  CHECK(g.get('X') == 10.5);
  CHECK(g.get('Y') == -3);
  CHECK(g.get('E') == 0.25);
  CHECK(g.get('F') == 1800);
  CHECK_FALSE(g.has('Z'));
  CHECK(g.comment == "move");
  g = parse_gcode_line("G28 X Y", e);
  CHECK(g.has('X'));
  g = parse_gcode_line("M104 S210 (inline) T0", e);
  CHECK(g.is('M', 104));
  CHECK(g.get('S') == 210);
  parse_gcode_line("G1 X1.2.3", e);
  CHECK(e == GcodeError::bad_number);
}

TEST_CASE("one straight move is one trapezoid") {
  const auto est = estimate_gcode("G1 X100 F6000\n", "t.gcode", limits(1000, 10));
  CHECK(est.seconds == doctest::Approx(trapezoid(100, 100, 1000, 10)).epsilon(1e-9));
  const auto tri = estimate_gcode("G1 X2 F6000\n", "t.gcode", limits(1000, 10));
  CHECK(tri.seconds == doctest::Approx(trapezoid(2, 100, 1000, 10)).epsilon(1e-9));
}

TEST_CASE("collinear moves flow, corners slow down, dwells add") {
  const auto one = estimate_gcode("G1 X100 F6000\n", "t", limits(1000, 10));
  const auto two = estimate_gcode("G1 X50 F6000\nG1 X100\n", "t", limits(1000, 10));
  CHECK(two.seconds == doctest::Approx(one.seconds).epsilon(1e-9));
  const auto corner = estimate_gcode("G1 X50 F6000\nG1 Y50\n", "t", limits(1000, 10));
  CHECK(corner.seconds > one.seconds);
  CHECK(corner.seconds == doctest::Approx(2 * trapezoid(50, 100, 1000, 10)).epsilon(1e-6));
  const auto dwell = estimate_gcode("G1 X100 F6000\nG4 P1500\nG4 S2\n", "t", limits(1000, 10));
  CHECK(dwell.seconds == doctest::Approx(one.seconds + 3.5));
}

TEST_CASE("limits in the file, relative moves, inches, arcs, layers and filament") {
  const auto fast = estimate_gcode("M204 P4000 T4000\nG1 X100 F6000\n", "t", limits(1000, 10));
  CHECK(fast.seconds == doctest::Approx(trapezoid(100, 100, 4000, 10)).epsilon(1e-9));
  const auto capped = estimate_gcode("M203 X50\nG1 X100 F6000\n", "t", limits(1000, 10));
  CHECK(capped.seconds == doctest::Approx(trapezoid(100, 50, 1000, 10)).epsilon(1e-9));
  const auto rel = estimate_gcode("G91\nG1 X50 F6000\nG1 X50\n", "t", limits(1000, 10));
  CHECK(rel.seconds == doctest::Approx(trapezoid(100, 100, 1000, 10)).epsilon(1e-9));
  const auto inch = estimate_gcode("G20\nG1 X1 F60\n", "t", limits(1e9, 1e9));
  CHECK(inch.seconds == doctest::Approx(1.0).epsilon(1e-6));  // 25.4 mm at 25.4 mm/s
  const auto arc = estimate_gcode("G1 X10 Y0 F600\nG3 X-10 Y0 I-10 J0\n", "t", limits(1e9, 1e9));
  CHECK(arc.seconds == doctest::Approx(1 + M_PI).epsilon(1e-6));  // 10 mm + a half circle of r 10 at 10 mm/s
  const auto layers = estimate_gcode(
      ";LAYER_CHANGE\nG1 X10 E1 F600\n;LAYER_CHANGE\nG1 X30 E3\nM83\nG1 E-1\nG1 E1\n", "t", limits(1e9, 1e9));
  REQUIRE(layers.layer_seconds.size() == 2);
  CHECK(layers.layer_seconds[0] == doctest::Approx(1));
  CHECK(layers.layer_seconds[1] == doctest::Approx(2 + 2.0 / 10));
  CHECK(layers.filament_mm == doctest::Approx(3));
  const auto waits = estimate_gcode("M190 S60\nM109 S200\n", "t");
  CHECK(waits.heating_waits == 2);
}

TEST_CASE("a malformed word is an error with its line") {
  CHECK_THROWS_WITH_AS(estimate_gcode("G28\nG1 X1.2.3 F100\n", "bad.gcode"),
                       "bad.gcode:2: malformed number in 'G1 X1.2.3 F100'", InputError);
}

TEST_CASE("arcs meet their neighbours along their tangents: a circle of four arcs flows like one move") {
  // Four quarter circles of r 20 (G3 from (20,0) round (0,0)): tangent at every junction, so no
  // corner slows them; from rest (the jerk speed along the start tangent, Y) and back to rest.
  const std::string quarters =
      "G92 X20 Y0\nG3 X0 Y20 I-20 J0 F6000\nG3 X-20 Y0 I0 J-20\nG3 X0 Y-20 I20 J0\nG3 X20 Y0 I0 J20\n";
  const auto arcs = estimate_gcode(quarters, "t", limits(1000, 10));
  CHECK(arcs.seconds == doctest::Approx(trapezoid(2 * M_PI * 20, 100, 1000, 10)).epsilon(1e-6));
  // Their chords, though shorter, take longer: they turn 90° at each junction and slow there.
  const auto square = estimate_gcode("G92 X20 Y0\nG1 X0 Y20 F6000\nG1 X-20 Y0\nG1 X0 Y-20\nG1 X20 Y0\n", "t",
                                     limits(1000, 10));
  CHECK(square.seconds > arcs.seconds);
}

TEST_CASE("per-command timings: one per command, in order, summing to the total") {
  std::vector<CommandTiming> commands;
  const auto est = estimate_gcode("; comment\nG28 ; home\nG1 X100 F6000\n\nG4 P500\n  M104 S200  \nG1 X0\n",
                                  "t", limits(1000, 10), &commands);
  REQUIRE(commands.size() == 5);
  double sum = 0;
  for (const CommandTiming& c : commands) sum += c.seconds;
  CHECK(sum == doctest::Approx(est.seconds).epsilon(1e-9));
  CHECK(commands[0].bytes == 3);  // "G28": comment and blanks are not sent
  CHECK(commands[2].seconds == doctest::Approx(0.5));
  CHECK(commands[3].bytes == 9);  // "M104 S200"
  CHECK(commands[3].seconds == 0);
  CHECK(commands[1].seconds == doctest::Approx(trapezoid(100, 100, 1000, 10)).epsilon(1e-9));
}

TEST_CASE("the printing area is the box of the extruding moves, as OctoPrint's analysis gives it") {
  // Travels (to the corner, up to z 20) and a retraction lie outside it; relative moves count.
  const GcodeEstimate e = estimate_gcode(
      "G28\nG1 Z0.3 F600\nG0 X10 Y20\nG1 X40 Y20 E1.5\nG1 E-0.8\nG0 X0 Y0\nG1 E0.8\nG91\nG1 X5 Y7 Z0.2 E0.2\n"
      "G90\nG0 Z20\n",
      "t");
  REQUIRE(e.printed);
  CHECK(e.printing_min[0] == doctest::Approx(0));
  CHECK(e.printing_max[0] == doctest::Approx(40));
  CHECK(e.printing_min[1] == doctest::Approx(0));
  CHECK(e.printing_max[1] == doctest::Approx(20));
  CHECK(e.printing_min[2] == doctest::Approx(0.3));
  CHECK(e.printing_max[2] == doctest::Approx(0.5));
  CHECK_FALSE(estimate_gcode("G28\nG0 X10 Y10\nG1 E5\n", "t").printed);  // priming in place prints no area
}

// A job's cancel reaches the estimator within a few thousand lines (issue 32 item 17): the
// plan phase times two plans on their G-code, which held a cancel for 2 s on a large model.
TEST_CASE("a cancelled or expired token stops the estimator with Cancelled") {
  std::string text;
  for (int i = 0; i < 20000; ++i) text += "G1 X" + std::to_string(i % 100) + " Y1 F3000\n";
  CancelToken token;
  CHECK_NOTHROW(estimate_gcode(text, "long.gcode", {}, nullptr, &token));
  token.cancel();
  CHECK_THROWS_AS(estimate_gcode(text, "long.gcode", {}, nullptr, &token), Cancelled);
  CancelToken expired;
  expired.expire_after(std::chrono::seconds(-1));  // a job's time limit, passed
  CHECK(expired.expired());
  CHECK_THROWS_AS(estimate_gcode(text, "long.gcode", {}, nullptr, &expired), Cancelled);
}
