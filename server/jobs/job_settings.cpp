// Job settings from the settings table: each JSON key is a row's key, checked by its type and
// range, set through the row, then checked as slice_model would before it loads anything.
#include "server/jobs/job_settings.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/common/input_error.hpp"
#include "core/pipeline/setting_table.hpp"
#include "server/common/domain_error.hpp"
#include "server/common/json_text.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

[[noreturn]] void bad(const std::string& message) {
  throw BadRequest("bad_settings", "settings: " + message);
}

// "'key' what" (built by appending: GCC 12 warns falsely on the chained operator+ here).
[[noreturn]] void bad_key(std::string_view key, const std::string& what) {
  std::string m = "'";
  m.append(key).append("' ").append(what);
  bad(m);
}

core::SettingValue value_of(const core::Setting& s, const json& v) {
  switch (s.type) {
    case core::SettingType::number:
    case core::SettingType::integer: {
      if (!v.is_number()) bad_key(s.key, "must be a number");
      const double x = v.get<double>();
      const bool integer = s.type == core::SettingType::integer;
      const auto bound = [integer](double b) {
        return integer ? json_text(json(static_cast<std::int64_t>(b))) : json_text(json(b));
      };
      if (!(x >= s.min && x <= s.max))
        bad_key(s.key, "must be between " + bound(s.min) + " and " + bound(s.max));
      if (integer && x != std::floor(x)) bad_key(s.key, "must be a whole number");
      if (integer) return static_cast<std::int64_t>(x);
      return x;
    }
    case core::SettingType::flag:
      if (!v.is_boolean()) bad_key(s.key, "must be true or false");
      return v.get<bool>();
    case core::SettingType::text:
    case core::SettingType::choice:
      break;
  }
  if (!v.is_string()) bad_key(s.key, "must be a string");
  return v.get<std::string>();
}

json json_of(const core::SettingValue& v) {
  return std::visit([](const auto& x) { return json(x); }, v);
}

}  // namespace

std::string quoted_setting(core::SettingId id) {
  return "'" + std::string(core::setting_key(id)) + "'";
}

JobSettings parse_job_settings(const std::string& text_in, std::size_t max_depth) {
  json j = json::object();
  if (!text_in.empty()) {
    try {
      j = parse_json_text(text_in, max_depth);
    } catch (const std::invalid_argument& e) {
      bad(e.what());
    }
    if (!j.is_object()) bad("must be a JSON object");
  }
  for (const auto& [key, value] : j.items()) {
    const core::Setting* s = core::setting_by_key(key);
    if (!s || !s->not_a_job_setting.empty()) bad("unknown key '" + key + "'");
  }
  core::Settings settings;
  try {
    for (const core::Setting& s : core::setting_table()) {
      if (!j.contains(s.key)) continue;
      for (core::SettingId other : s.excludes)
        if (j.contains(core::setting_key(other)))
          bad("give one of " + quoted_setting(s.id) + " and " + quoted_setting(other) + ", not both");
      s.set(settings, value_of(s, j.at(std::string(s.key))));
    }
    // A job's mistakes are a 400 now rather than a failed job later, on the printer's limits.
    if (const auto printer = core::builtin_printer(settings.printer))
      core::check_slice_settings(settings.slice, *printer);
  } catch (const core::InputError& e) {
    bad(e.spelled(quoted_setting));
  }
  // Canonical form: the table's settings that a job always holds, and those given or changed,
  // keys sorted (nlohmann's object is ordered); equal settings share one result.
  json canon = json::object();
  for (const auto& [s, v] : core::canonical_values(settings)) canon[std::string(s->key)] = json_of(v);
  JobSettings out;
  out.printer = settings.printer;
  out.slice = settings.slice;
  out.canonical = json_text(canon);
  return out;
}

}  // namespace salient::server
