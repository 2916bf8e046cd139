// SettingId's name table and the placeholder speller.
#include "core/common/setting_id.hpp"

#include <array>
#include <utility>

#include "core/common/name_table.hpp"

namespace salient::core {
namespace {

constexpr NameTable<SettingId, 27> keys = {{
    {SettingId::printer, "printer"},
    {SettingId::planner, "planner"},
    {SettingId::up, "up"},
    {SettingId::height, "height"},
    {SettingId::scale, "scale"},
    {SettingId::min_layer, "min_layer"},
    {SettingId::max_layer, "max_layer"},
    {SettingId::grid, "grid"},
    {SettingId::rho, "rho"},
    {SettingId::layers, "layers"},
    {SettingId::layer_height, "layer_height"},
    {SettingId::metric, "metric"},
    {SettingId::objective, "objective"},
    {SettingId::saliency, "saliency"},
    {SettingId::saliency_file, "saliency_file"},
    {SettingId::seed, "seed"},
    {SettingId::segment, "segment"},
    {SettingId::segment_depth, "segment_depth"},
    {SettingId::segment_planes, "segment_planes"},
    {SettingId::walls, "walls"},
    {SettingId::infill, "infill"},
    {SettingId::line_width, "line_width"},
    {SettingId::top_thickness, "top_thickness"},
    {SettingId::bottom_thickness, "bottom_thickness"},
    {SettingId::combine_infill, "combine_infill"},
    {SettingId::support, "support"},
    {SettingId::support_angle, "support_angle"},
}};

}  // namespace

std::string_view setting_key(SettingId id) {
  return name_in(keys, id);
}

std::optional<SettingId> setting_from_key(std::string_view key) {
  return value_in(keys, key);
}

std::string spell_settings(std::string_view text, const SettingSpeller& spell) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t open = text.find('{', i);
    const std::size_t close = open == std::string_view::npos ? open : text.find('}', open);
    if (close == std::string_view::npos) break;
    out.append(text.substr(i, open - i));
    const auto id = setting_from_key(text.substr(open + 1, close - open - 1));
    out.append(id ? spell(*id) : std::string(text.substr(open, close - open + 1)));
    i = close + 1;
  }
  out.append(text.substr(std::min(i, text.size())));
  return out;
}

}  // namespace salient::core
