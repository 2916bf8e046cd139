// ExtrusionCounter: the filament a print pushed up to a command, as the history records it.
#include "protocol/marlin/extrusion_counter.hpp"

#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

#include "core/gcode/time_estimator.hpp"

using salient::protocol::Program;
using salient::protocol::marlin::ExtrusionCounter;

namespace {

// A file with layers of extruding moves, retractions and primes, G92 E0 resets and a switch to
// relative extrusion halfway, as slicers write them.
std::string file(std::mt19937& rng, int moves) {
  std::uniform_real_distribution<double> len(0.01, 2.0);
  std::string g = "G21\nG90\nM82\nG92 E0\nG1 Z0.2 F600\n";
  double e = 0;
  bool relative = false;
  for (int i = 0; i < moves; ++i) {
    if (i == moves / 2) g += "M83 ; relative from here\n", relative = true;
    if (i % 50 == 0 && !relative) g += "G92 E0\n", e = 0;
    const double d = len(rng);
    e += d;
    g += "G1 X" + std::to_string(i % 100) + " Y" + std::to_string(i % 37) + " E" +
         std::to_string(relative ? d : e) + " F1800\n";
    if (i % 17 == 0) {  // retract, travel, prime
      g += relative
               ? "G1 E-0.8 F2400\nG0 X5 Y5\nG1 E0.8 F2400\n"
               : "G1 E" + std::to_string(e - 0.8) + " F2400\nG0 X5 Y5\nG1 E" + std::to_string(e) + " F2400\n";
    }
  }
  return g;
}

}  // namespace

TEST_CASE("the filament pushed agrees with the time estimator's over whole files") {
  std::mt19937 rng(7);
  for (int n : {1, 10, 300, 2000}) {
    const std::string g = file(rng, n);
    const Program program = Program::parse(g);
    ExtrusionCounter c(program);
    c.advance_to(program.size());
    const double want = salient::core::estimate_gcode(g, "test").filament_mm;
    CHECK(c.extruded_mm() == doctest::Approx(want).epsilon(1e-9));
    CHECK(c.extruded_mm() > 0);
  }
}

TEST_CASE("counted in any steps it is the same, it never goes back, and a resume counts only the rest") {
  std::mt19937 rng(11);
  const Program program = Program::parse(file(rng, 800));
  ExtrusionCounter whole(program);
  const double all = whole.advance_to(program.size() + 10);  // past the end: the end
  ExtrusionCounter steps(program);
  std::uniform_int_distribution<std::size_t> step(0, 40);
  double sum = 0;
  for (std::size_t at = 0; at < program.size();) {
    at += step(rng);
    sum += steps.advance_to(at);
    CHECK(steps.advance_to(at / 2) == 0);  // backwards counts nothing
  }
  CHECK(sum == doctest::Approx(all));
  CHECK(steps.extruded_mm() == doctest::Approx(all));
  // Resumed at k: the state of the first k commands, the filament of the rest.
  for (std::size_t k : {std::size_t{0}, program.size() / 3, program.size() / 2 + 7, program.size()}) {
    ExtrusionCounter head(program), resumed(program);
    const double before = head.advance_to(k);
    resumed.skip_to(k);
    CHECK(resumed.extruded_mm() == 0);
    CHECK(before + resumed.advance_to(program.size()) == doctest::Approx(all));
  }
}

TEST_CASE("retractions net out, G92 resets, relative modes and inches are followed") {
  const Program p = Program::parse(
      "G92 E0\nG1 X1 E5\nG1 E4\nG1 E5\nG92 E0\nG1 X2 E2 ; 7 so far\nG91\nG1 X1 E1\nG90\n"
      "M83\nG1 X3 E0.5\nM82\nG92 E10\nG1 X4 E11\nG20\nG92 E0\nG1 X5 E0.1\nG21\nG0 X0\nM104 S200\n");
  ExtrusionCounter c(p);
  CHECK(c.advance_to(4) == doctest::Approx(5));            // 5, retract 1, prime 1
  CHECK(c.advance_to(6) == doctest::Approx(2));            // after the reset: 2
  CHECK(c.advance_to(9) == doctest::Approx(1));            // G91 makes E relative too
  CHECK(c.advance_to(12) == doctest::Approx(0.5));         // M83
  CHECK(c.advance_to(14) == doctest::Approx(1));           // from E10 to E11
  CHECK(c.advance_to(p.size()) == doctest::Approx(2.54));  // G20: 0.1 inch
}

TEST_CASE("the nozzle's height follows G0/G1 Z, G91, G92 Z, G28 and inches") {
  const Program p = Program::parse(
      "M104 S200\nG28\nG1 Z5 F600\nG1 X1 Y1 E1\nG91\nG1 Z0.2\nG90\nG92 Z10\nG28 X\nG1 Z12\nG28 Z\n"
      "G20\nG1 Z1\n");
  ExtrusionCounter c(p);
  c.advance_to(1);
  CHECK(!c.z_mm());  // nothing told yet
  const std::vector<double> want = {0, 5, 5, 5, 5.2, 5.2, 10, 10, 12, 0, 0, 25.4};
  for (std::size_t i = 0; i < want.size(); ++i) {
    c.advance_to(i + 2);
    REQUIRE(c.z_mm());
    CHECK(*c.z_mm() == doctest::Approx(want[i]));
  }
}
