// JobProgress: the core's reports become the job's phases in order, over the whole job, thinned out.
#include "server/jobs/job_progress.hpp"

#include <doctest/doctest.h>

using namespace salient::server;
using clock_type = std::chrono::steady_clock;

TEST_CASE("the core's phases map onto the job's, each in its span of the whole job") {
  JobProgress p;
  auto t = clock_type::now();
  const auto at = [&](std::string_view phase, double f) {
    t += std::chrono::seconds(1);
    return p.report(phase, f, t);
  };
  CHECK(at("load", 0)->phase == JobPhase::load);
  CHECK(at("lee05", 0.5)->phase == JobPhase::saliency);
  CHECK(at("lee05", 0.5 + 0.001) == std::nullopt);  // less than 2 % on
  CHECK(at("profile", 1)->overall == doctest::Approx(0.4));
  const auto planner = at("exact", 0.5);  // a planner's own name is the plan phase
  CHECK(planner->phase == JobPhase::plan);
  CHECK(planner->overall == doctest::Approx(0.5));
  CHECK(at("gcode", 1)->overall == doctest::Approx(1));
  CHECK(at("toolpaths", 0) == std::nullopt);  // never back within a phase
  JobProgress fresh;
  const auto first = fresh.report("toolpaths", 0, t);
  REQUIRE(first);
  CHECK(to_string(first->phase) == "toolpaths");
}

TEST_CASE("orient takes the first 30 % and under SegOpt its planners' reports are hidden") {
  JobProgress p;
  auto t = clock_type::now();
  const auto at = [&](std::string_view phase, double f) {
    t += std::chrono::seconds(1);
    return p.report(phase, f, t);
  };
  const auto oriented = at("orient", 1);
  CHECK(oriented->phase == JobPhase::orient);
  CHECK(oriented->overall == doctest::Approx(0.3));
  CHECK(at("load", 0)->overall == doctest::Approx(0.3));
  CHECK(at("segment", 0)->phase == JobPhase::plan);
  CHECK(at("exact", 0.9) == std::nullopt);
  CHECK(at("profile", 0.9) == std::nullopt);
  CHECK(at("segment", 1)->overall == doctest::Approx(0.3 + 0.7 * 0.6));
  CHECK(at("toolpaths", 0)->phase == JobPhase::toolpaths);
}

TEST_CASE("within one phase, a report less than 100 ms after the last stored is not stored") {
  JobProgress p;
  const auto t = clock_type::now();
  CHECK(p.report("load", 0, t));
  CHECK_FALSE(p.report("load", 0.9, t + std::chrono::milliseconds(50)));
  CHECK(p.report("saliency", 0, t + std::chrono::milliseconds(60)));  // a new phase always is
}

TEST_CASE("job states and phases: one name each, both ways") {
  for (const auto& [state, name] : job_state_names) CHECK(job_state_from(name) == state);
  for (const auto& [phase, name] : job_phase_names) CHECK(job_phase_from(name) == phase);
  CHECK(to_string(JobPhase::none).empty());
  CHECK_FALSE(job_state_from("cancelling"));
}
