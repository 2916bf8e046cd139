// A job's state and phase, and their one name table each: the text in the API's JSON, in the
// database and in events. Standard library (and core/common/name_table.hpp) only, so that the
// CLI reads the daemon's JSON with the same names (clients/cli/client_commands.cpp).
//   States: queued → running → done | failed | cancelled.
//   Phases of a running job, in order: load, orient (only with "up": "auto"), saliency, plan
//   (the z-profile, the planner and, with "segment", SegOpt), toolpaths (and G-code); none while
//   queued (the empty name).
#pragma once

#include <array>
#include <optional>
#include <string_view>
#include <utility>

#include "core/common/name_table.hpp"

namespace salient::server {

enum class JobState { queued, running, done, failed, cancelled };
enum class JobPhase { none, load, orient, saliency, plan, toolpaths };

inline constexpr core::NameTable<JobState, 5> job_state_names{{
    {JobState::queued, "queued"},
    {JobState::running, "running"},
    {JobState::done, "done"},
    {JobState::failed, "failed"},
    {JobState::cancelled, "cancelled"},
}};
inline constexpr core::NameTable<JobPhase, 6> job_phase_names{{
    {JobPhase::none, ""},
    {JobPhase::load, "load"},
    {JobPhase::orient, "orient"},
    {JobPhase::saliency, "saliency"},
    {JobPhase::plan, "plan"},
    {JobPhase::toolpaths, "toolpaths"},
}};

constexpr std::string_view to_string(JobState s) {
  return core::name_in(job_state_names, s);
}
constexpr std::string_view to_string(JobPhase p) {
  return core::name_in(job_phase_names, p);
}
// Empty for a name not in the table (a newer daemon's, or a typo in a query).
constexpr std::optional<JobState> job_state_from(std::string_view name) {
  return core::value_in(job_state_names, name);
}
constexpr std::optional<JobPhase> job_phase_from(std::string_view name) {
  return core::value_in(job_phase_names, name);
}

constexpr bool finished(JobState s) {
  return s == JobState::done || s == JobState::failed || s == JobState::cancelled;
}

}  // namespace salient::server
