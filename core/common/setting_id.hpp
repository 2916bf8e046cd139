// SettingId: every slicing setting by name, so that core can say which one is at fault without
// spelling it as one front end does ("--grid" in the CLI, "grid" in a job's JSON).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace salient::core {

// One per row of the settings table (core/pipeline/setting_table.hpp), in its order.
enum class SettingId {
  printer,
  planner,
  up,
  height,
  scale,
  min_layer,
  max_layer,
  grid,
  rho,
  layers,
  layer_height,
  metric,
  objective,
  saliency,
  saliency_file,
  seed,
  segment,
  segment_depth,
  segment_planes,
  walls,
  infill,
  line_width,
  top_thickness,
  bottom_thickness,
  combine_infill,
  support,
  support_angle,
};

// The name table: the JSON key ("min_layer") of each setting, and back.
std::string_view setting_key(SettingId id);
std::optional<SettingId> setting_from_key(std::string_view key);

// How a front end names a setting: "--grid" (CLI), "'grid'" (a job's 400).
using SettingSpeller = std::function<std::string(SettingId)>;

// `text` with each placeholder "{key}" of a known setting replaced by spell(id); other braces
// are left as they are. Core messages name settings this way: "{grid}: does not divide {min_layer}".
std::string spell_settings(std::string_view text, const SettingSpeller& spell);

}  // namespace salient::core
