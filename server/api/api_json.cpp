#include "server/api/api_json.hpp"

namespace salient::server {

using nlohmann::json;

json parse_json_body(const HttpRequest& request, std::size_t max_bytes, std::size_t max_depth) {
  if (request.body.size() > max_bytes)
    throw ApiError(413, "too_large", "the JSON body exceeds " + std::to_string(max_bytes) + " bytes");
  if (request.body.find_first_not_of(" \t\r\n") == std::string::npos) return json::object();
  bool too_deep = false;
  // The parser tells each value's depth as it goes: stop at once rather than build a deep tree.
  const json::parser_callback_t check = [&](int depth, json::parse_event_t, json&) {
    if (static_cast<std::size_t>(depth) > max_depth) {
      too_deep = true;
      throw std::invalid_argument("too deep");
    }
    return true;
  };
  json j;
  try {
    j = json::parse(request.body, check);
  } catch (const std::exception& e) {
    if (too_deep) throw ApiError(400, "bad_request", "the JSON body is nested deeper than " + std::to_string(max_depth));
    throw ApiError(400, "bad_request", std::string("the body is not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw ApiError(400, "bad_request", "the body must be a JSON object");
  return j;
}

json job_json(const Job& j) {
  json out = {{"id", j.id},
              {"state", to_string(j.state)},
              {"phase", j.phase},
              {"progress", j.progress},
              {"filename", j.filename},
              {"settings", json::parse(j.settings, nullptr, false)},
              {"attempts", j.attempts},
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
