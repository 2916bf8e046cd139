// Job settings: the JSON a client sends with a model, checked and turned into the core's
// SliceSettings. Unknown keys and bad values are refused with a message naming the key.
#pragma once

#include <string>

#include "core/pipeline/slice_pipeline.hpp"

namespace salient::server {

struct JobSettings {
  std::string printer = "generic-i3";  // printer profile for slicing
  core::SliceSettings slice;
  std::string canonical;  // the settings as canonical JSON (sorted keys, defaults filled in)
};

// Throws BadRequest ("bad_settings") naming the key (core messages spell settings 'key'); `json` may be empty
// (all defaults).
JobSettings parse_job_settings(const std::string& json, std::size_t max_depth = 32);

}  // namespace salient::server
