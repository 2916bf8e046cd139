#include "server/jobs/job_progress.hpp"

#include <algorithm>

namespace salient::server {
namespace {

// Where each phase the core reports lies in the whole job, and the job phase it belongs to. Any
// other name is the plan phase's (the planners report their own names).
enum class Kind {
  step,     // rescaled into the last 70 % after "orient"; hidden while SegOpt runs
  orient,   // "up": "auto": the first 30 % of the job, not rescaled
  segment,  // SegOpt: from here on its own progress stands for its planners'
  output,   // toolpaths and G-code: shown after SegOpt too
};
struct Span {
  std::string_view reported;
  JobPhase phase;
  double from, to;
  Kind kind;
};
constexpr Span spans[] = {
    {"load", JobPhase::load, 0.0, 0.05, Kind::step},
    {"orient", JobPhase::orient, 0.0, 0.3, Kind::orient},
    {"saliency", JobPhase::saliency, 0.05, 0.35, Kind::step},
    {"lee05", JobPhase::saliency, 0.05, 0.35, Kind::step},
    {"profile", JobPhase::plan, 0.35, 0.4, Kind::step},
    {"segment", JobPhase::plan, 0.4, 0.6, Kind::segment},
    {"toolpaths", JobPhase::toolpaths, 0.6, 0.95, Kind::output},
    {"gcode", JobPhase::toolpaths, 0.95, 1.0, Kind::output},
};
constexpr Span planner_span{"", JobPhase::plan, 0.4, 0.6, Kind::step};

const Span& span_of(std::string_view reported) {
  for (const Span& s : spans)
    if (s.reported == reported) return s;
  return planner_span;
}

}  // namespace

std::optional<JobProgress::Update> JobProgress::report(std::string_view reported, double fraction,
                                                       std::chrono::steady_clock::time_point now) {
  const Span& s = span_of(reported);
  if (s.kind == Kind::segment)
    segmenting_ = true;
  else if (segmenting_ && s.kind != Kind::output)
    return std::nullopt;
  double from = s.from, to = s.to;
  if (s.kind == Kind::orient)
    oriented_ = true;
  else if (oriented_)
    from = 0.3 + 0.7 * from, to = 0.3 + 0.7 * to;
  const double overall = from + (to - from) * std::clamp(fraction, 0.0, 1.0);
  if (last_phase_ == s.phase &&
      (overall - last_overall_ < 0.02 || now - last_write_ < std::chrono::milliseconds(100)))
    return std::nullopt;
  last_phase_ = s.phase, last_overall_ = overall, last_write_ = now;
  return Update{s.phase, overall};
}

}  // namespace salient::server
