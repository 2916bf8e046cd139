#include "server/api/octoprint_settings.hpp"

#include <array>
#include <string_view>

namespace salient::server {

using nlohmann::json;

namespace {

// sdSupport and the like describe the daemon, not a preference: they are not writable.
constexpr std::array<std::string_view, 4> kWritable = {"appearance", "webcam", "temperature",
                                                       "gcodeAnalysis"};
constexpr std::size_t kMaxString = 256, kMaxItems = 32;

bool same_kind(const json& a, const json& b) {
  if (a.is_number() && b.is_number()) return true;
  return a.type() == b.type();
}

json accept(const json& defaults, const json& value) {
  if (defaults.is_object()) {
    json out = json::object();
    if (!value.is_object()) return out;
    for (const auto& [key, v] : value.items()) {
      const auto d = defaults.find(key);
      if (d == defaults.end()) continue;
      json kept = accept(*d, v);
      if (!kept.is_null() && !(kept.is_object() && kept.empty())) out[key] = std::move(kept);
    }
    return out;
  }
  if (!same_kind(defaults, value)) return nullptr;
  if (value.is_string() && value.get_ref<const std::string&>().size() > kMaxString) return nullptr;
  if (value.is_array() && (value.size() > kMaxItems || value.dump().size() > 64 * kMaxString)) return nullptr;
  return value;
}

}  // namespace

json accepted_settings(const json& defaults, const json& body) {
  json out = json::object();
  for (std::string_view section : kWritable) {
    const std::string key(section);
    if (!body.contains(key) || !defaults.contains(key)) continue;
    json kept = accept(defaults.at(key), body.at(key));
    if (kept.is_object() && !kept.empty()) out[key] = std::move(kept);
  }
  return out;
}

}  // namespace salient::server
