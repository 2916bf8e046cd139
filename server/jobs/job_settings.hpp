// Job settings: the JSON a client sends with a model, checked and turned into the core's
// SliceSettings. The keys are the settings table's (core/pipeline/setting_table.hpp); unknown
// keys and bad values are refused with a message naming the key.
#pragma once

#include <string>

#include "core/common/setting_id.hpp"
#include "core/pipeline/slice_pipeline.hpp"

namespace salient::server {

struct JobSettings {
  std::string printer = "generic-i3";  // printer profile for slicing
  core::SliceSettings slice;
  // The settings as canonical JSON: sorted keys, the table's `always` settings with their
  // defaults, the others only when given or changed (equal canonical settings share one result).
  std::string canonical;
};

// How a job's messages name a setting: 'grid' (its key in the settings JSON).
std::string quoted_setting(core::SettingId id);

// Throws BadRequest ("bad_settings") naming the key, as 'grid' (also in core's messages, which
// are checked here on the built-in printer's layer limits); `json` may be empty (all defaults).
JobSettings parse_job_settings(const std::string& json, std::size_t max_depth = 32);

}  // namespace salient::server
