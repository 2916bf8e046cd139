// The slice's figures as JSON, named as a job's result has named them since its first version.
#include "core/pipeline/slice_result_json.hpp"

#include <nlohmann/json.hpp>

#include "core/export/plan_json.hpp"

namespace salient::core {
namespace {

using nlohmann::json;

json orientation_object(const OrientationReport& o) {
  json candidates = json::array();
  for (const OrientationScore& c : o.candidates)
    candidates.push_back({{"up", direction_text(c.up)},
                          {"minutes", c.minutes},
                          {"layers", c.layers},
                          {"time_score", c.time_score},
                          {"volume_score", c.volume_score},
                          {"stability_score", c.stability_score},
                          {"score", c.score}});
  return {{"up", o.up}, {"candidates", candidates}};
}

}  // namespace

std::string slice_result_json(const SliceResult& r, const std::string& printer_id,
                              const SettingSpeller& spell, int indent) {
  json warnings = json::array();
  for (const SliceWarning& w : r.warnings)
    warnings.push_back({{"code", w.code}, {"message", spell_settings(w.message, spell)}});
  const json j{
      {"layers", r.layers},
      {"finest_layers", r.finest_layers},
      {"saving", r.finest_layers > 0 ? 1.0 - double(r.layers) / r.finest_layers : 0.0},
      {"print_seconds", r.print_seconds},
      {"filament_mm", r.filament_mm},
      {"stream",
       {{"peak_commands_per_second", r.stream.peak_commands_per_second},
        {"link_commands_per_second", r.stream.link_commands_per_second},
        {"baud", r.stream.baud},
        {"starves", r.stream.starves()}}},
      {"error", r.error},
      {"rsmd", r.rsmd},
      {"open_contours", r.open_contours},
      {"dropped_faces", r.dropped_faces},
      {"warnings", warnings},
      {"saliency_method", r.plan.saliency_method},
      {"orientation", r.orientation ? orientation_object(*r.orientation) : json(nullptr)},
      {"segmentation",
       r.plan.segmentation ? json::parse(segmentation_json(*r.plan.segmentation)) : json(nullptr)},
      {"times", r.plan.times ? json::parse(times_json(*r.plan.times)) : json(nullptr)},
      {"printer", printer_id},
  };
  std::string out = j.dump(indent, ' ', false, json::error_handler_t::replace);
  if (indent >= 0) out += '\n';
  return out;
}

}  // namespace salient::core
