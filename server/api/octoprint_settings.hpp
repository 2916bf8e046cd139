// What of OctoPrint's settings a client may write (POST /api/settings): the keys FDM Monster,
// OctoPod and the web clients change (appearance, webcam, temperature presets, gcodeAnalysis.runAt), each
// only with the type its default has. Pure; the routes keep the result in the store. Included from .cpp.
#pragma once

#include <nlohmann/json.hpp>

namespace salient::server {

// The part of `body` that `defaults` has, in the writable sections, with the same JSON type
// (strings up to 256 bytes, arrays up to 32 items); everything else is left out quietly, as
// OctoPrint ignores keys it does not know. `body` must be an object (the caller checks).
nlohmann::json accepted_settings(const nlohmann::json& defaults, const nlohmann::json& body);

}  // namespace salient::server
