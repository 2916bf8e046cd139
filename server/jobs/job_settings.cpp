#include "server/jobs/job_settings.hpp"

#include <nlohmann/json.hpp>
#include <set>

#include "core/mesh/placement.hpp"
#include "server/http/json_text.hpp"
#include "server/http/router.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

[[noreturn]] void bad(const std::string& message) {
  throw ApiError(400, "bad_settings", "settings: " + message);
}

// "'key' what" (built by appending: GCC 12 warns falsely on the chained operator+ here).
[[noreturn]] void bad_key(const char* key, const char* what) {
  std::string m = "'";
  m.append(key).append("' ").append(what);
  bad(m);
}

double number(const json& j, const char* key, double min, double max) {
  const json& v = j.at(key);
  if (!v.is_number()) bad_key(key, "must be a number");
  const double x = v.get<double>();
  if (!(x >= min && x <= max))
    bad_key(key, ("must be between " + json_text(json(min)) + " and " + json_text(json(max))).c_str());
  return x;
}

std::string text(const json& j, const char* key) {
  const json& v = j.at(key);
  if (!v.is_string()) bad_key(key, "must be a string");
  return v.get<std::string>();
}

bool flag(const json& j, const char* key) {
  const json& v = j.at(key);
  if (!v.is_boolean()) bad_key(key, "must be true or false");
  return v.get<bool>();
}

}  // namespace

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
  JobSettings s;
  core::SliceSettings& c = s.slice;
  core::PlanOptions& p = c.plan;
  static const std::set<std::string> known = {
      "printer", "planner", "metric",        "saliency",  "rho",       "layers",       "layer_height",
      "up",      "height",  "scale",         "min_layer", "max_layer", "grid",         "walls",
      "infill",  "support", "support_angle", "seed",      "segment",   "segment_depth"};
  for (const auto& [key, value] : j.items())
    if (!known.count(key)) bad("unknown key '" + key + "'");
  if (j.contains("printer")) s.printer = text(j, "printer");
  if (j.contains("planner")) p.planner = text(j, "planner");
  if (j.contains("metric")) p.metric = text(j, "metric");
  if (j.contains("saliency")) p.saliency = text(j, "saliency");
  if (j.contains("up")) p.mesh.up = text(j, "up");
  if (j.contains("rho")) p.rho = number(j, "rho", 0, 1);
  if (j.contains("layers")) p.layers = static_cast<int>(number(j, "layers", 1, 100000));
  if (j.contains("layer_height")) p.layer_height = number(j, "layer_height", 0.01, 10);
  if (int(j.contains("rho")) + int(j.contains("layers")) + int(j.contains("layer_height")) > 1)
    bad("give one of 'rho', 'layers' and 'layer_height'");
  if (j.contains("height")) p.mesh.height = number(j, "height", 0.1, 10000);
  if (j.contains("scale")) p.mesh.scale = number(j, "scale", 1e-6, 1e6);
  if (j.contains("min_layer"))
    p.min_layer = number(j, "min_layer", 0.01, 10), c.min_layer_from_printer = false;
  if (j.contains("max_layer"))
    p.max_layer = number(j, "max_layer", 0.01, 10), c.max_layer_from_printer = false;
  if (j.contains("grid")) p.grid = number(j, "grid", 0.001, 1);
  if (j.contains("seed")) p.seed = static_cast<std::uint64_t>(number(j, "seed", 0, 1e15));
  if (j.contains("walls")) c.toolpaths.walls = static_cast<int>(number(j, "walls", 1, 20));
  if (j.contains("infill")) c.toolpaths.infill_density = number(j, "infill", 0, 1);
  if (j.contains("support")) c.support = flag(j, "support");
  if (j.contains("segment")) p.segment = flag(j, "segment");
  if (j.contains("segment_depth")) p.segment_depth = static_cast<int>(number(j, "segment_depth", 1, 4));
  if (p.segment && (p.layers || p.layer_height))
    bad("'segment' works to a quality target ('rho'), not to a layer count");
  if (p.segment && p.planner == "ha13")
    bad("'segment' cannot use the ha13 planner (it cuts the whole model's sections)");
  if (j.contains("support_angle")) c.support_settings.angle = number(j, "support_angle", 0, 89);
  if (p.metric != "area" && p.metric != "paper") bad("'metric' must be area or paper");
  if (p.saliency != "spectral" && p.saliency != "lee05" && p.saliency != "uniform")
    bad("'saliency' must be spectral, lee05 or uniform");
  if (!core::parse_up_axis(p.mesh.up) && !core::parse_up_direction(p.mesh.up) && p.mesh.up != "auto")
    bad("'up' must be x, y, z, auto or a direction like \"0,-1,0.2\"");
  if (!core::make_planner(p.planner)) bad("unknown planner '" + p.planner + "'");
  // Canonical form: every setting, defaults included, keys sorted (nlohmann's object is ordered).
  json canon = {{"printer", s.printer},
                {"planner", p.planner},
                {"metric", p.metric},
                {"saliency", p.saliency},
                {"up", p.mesh.up},
                {"scale", p.mesh.scale},
                {"grid", p.grid},
                {"seed", p.seed},
                {"walls", c.toolpaths.walls},
                {"infill", c.toolpaths.infill_density},
                {"support", c.support},
                {"support_angle", c.support_settings.angle}};
  if (p.rho) canon["rho"] = *p.rho;
  if (p.segment) canon["segment"] = true;  // only when asked: older jobs keep their canonical form
  if (p.segment && p.segment_depth != 1) canon["segment_depth"] = p.segment_depth;
  if (p.layers) canon["layers"] = *p.layers;
  if (p.layer_height) canon["layer_height"] = *p.layer_height;
  if (p.mesh.height) canon["height"] = *p.mesh.height;
  if (!c.min_layer_from_printer) canon["min_layer"] = p.min_layer;
  if (!c.max_layer_from_printer) canon["max_layer"] = p.max_layer;
  s.canonical = json_text(canon);
  return s;
}

}  // namespace salient::server
