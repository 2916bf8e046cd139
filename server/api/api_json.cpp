#include "server/api/api_json.hpp"

#include "server/common/json_text.hpp"

namespace salient::server {

using nlohmann::json;

json parse_json_body(const HttpRequest& request, std::size_t max_bytes, std::size_t max_depth) {
  if (request.body.size() > max_bytes)
    throw ApiError(413, "too_large", "the JSON body exceeds " + std::to_string(max_bytes) + " bytes");
  if (request.body.find_first_not_of(" \t\r\n") == std::string::npos) return json::object();
  json j;
  try {
    j = parse_json_text(request.body, max_depth);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, "bad_request", std::string("the JSON body is ") + e.what());
  }
  if (!j.is_object()) throw ApiError(400, "bad_request", "the body must be a JSON object");
  return j;
}

std::string string_field(const json& body, const char* key, const std::string& fallback) {
  const auto it = body.find(key);
  if (it == body.end()) return fallback;
  if (!it->is_string()) throw ApiError(400, "bad_request", std::string("'") + key + "' must be a string");
  return it->get<std::string>();
}

namespace {

// Why the job went back to the queue, each time: [{"node", "at", "reason"}], oldest first.
json requeues_json(const std::string& text) {
  json list = json::parse(text, nullptr, false);
  return list.is_array() ? list : json::array();
}

}  // namespace

json job_json(const Job& j) {
  json out = {{"id", j.id},
              {"state", to_string(j.state)},
              {"phase", to_string(j.phase)},
              {"progress", j.progress},
              {"filename", j.filename},
              {"settings", json::parse(j.settings, nullptr, false)},
              {"attempts", j.attempts},
              {"node", j.node ? json(*j.node) : json(nullptr)},
              {"requeues", requeues_json(j.requeues)},
              {"created_at", j.created_at},
              {"started_at", j.started_at ? json(*j.started_at) : json(nullptr)},
              {"finished_at", j.finished_at ? json(*j.finished_at) : json(nullptr)},
              {"error", j.error ? json(*j.error) : json(nullptr)}};
  if (j.result) {
    json r = json::parse(*j.result, nullptr, false);
    if (!r.is_discarded()) {
      out["result"] = r;
      const std::string base = "/api/v1/jobs/" + j.id;
      out["links"] = {{"gcode", base + "/gcode"},
                      {"plan", base + "/plan"},
                      {"plot", base + "/plot.svg"},
                      {"model", base + "/model.3mf"},
                      {"saliency", base + "/saliency.ply"}};
    }
  }
  return out;
}

}  // namespace salient::server
