// Build information the daemon reports (version, API level).
#pragma once

#include <string_view>

namespace salient::server {

std::string_view version();
// The REST API level served under /api/v1.
constexpr int api_level = 1;
// The OctoPrint version whose API salientd serves: /api/version's "server" and /api/server's
// "version" both tell this one (clients check it against features they need).
constexpr std::string_view octoprint_version = "1.10.0";
// The OctoPrint API version /api/version tells, and the Zeroconf announcement's "api" record.
constexpr std::string_view octoprint_api_version = "0.1";

}  // namespace salient::server
