// Build information the daemon reports (version, API level).
#pragma once

#include <string_view>

namespace salient::server {

std::string_view version();
// The REST API level served under /api/v1.
constexpr int api_level = 1;

}  // namespace salient::server
