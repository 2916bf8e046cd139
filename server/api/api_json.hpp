// JSON helpers shared by the route files (included from .cpp files only): responses, request
// bodies checked for size, depth and shape, and the job document that both GET /api/v1/jobs/{id}
// and the "job" events carry.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "server/common/json_text.hpp"
#include "server/http/router.hpp"
#include "server/jobs/job.hpp"

namespace salient::server {

inline HttpResponse json_response(int status, const nlohmann::json& j) {
  return HttpResponse::text(status, json_text(j), "application/json");
}

// The body as a JSON object: 413 above `max_bytes`, 400 when it is not JSON, nested deeper than
// `max_depth`, or not an object. An empty body is an empty object.
nlohmann::json parse_json_body(const HttpRequest& request, std::size_t max_bytes, std::size_t max_depth);

nlohmann::json job_json(const Job& job);

// body[key] as a string, `fallback` when absent; 400 naming the key when it is anything else.
std::string string_field(const nlohmann::json& body, const char* key, const std::string& fallback);

// {"commands": ["G28", …]} or {"command": "G28"}: one-line G-code commands (400 otherwise).
std::vector<std::string> parse_commands(const nlohmann::json& body);

}  // namespace salient::server
