#include "core/export/plan_json.hpp"

#include <nlohmann/json.hpp>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

using nlohmann::json;

json or_null(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

std::string text_of(const json& j, int indent) {
  return j.dump(indent, ' ', false, json::error_handler_t::replace) + (indent >= 0 ? "\n" : "");
}

json segmentation_object(const SegmentationReport& r) {
  json regions = json::array();
  for (const SegmentationReport::Region& region : r.regions) {
    json clip = json::array();
    for (const auto& p : region.clip) clip.push_back({p[0], p[1]});
    regions.push_back({{"side", region.side},
                       {"sub", region.sub},
                       {"z_bottom", region.z_bottom},
                       {"z_top", region.z_top},
                       {"layers", region.layers},
                       {"E", region.error},
                       {"epsilon", region.epsilon},
                       {"boundaries", region.boundaries},
                       {"clip", clip}});
  }
  json slabs = json::array();
  for (const SegmentationReport::Slab& s : r.slabs)
    slabs.push_back({{"z_bottom", s.z_bottom},
                     {"z_top", s.z_top},
                     {"merged", s.merged},
                     {"loss", {s.loss[0], s.loss[1]}}});
  json j = {{"cut", r.cut},
            {"note", r.note},
            {"whole_seconds", r.whole_seconds},
            {"parts_seconds", r.parts_seconds},
            {"seconds", r.seconds},
            {"regions", regions},
            {"slabs", slabs}};
  if (r.plane)
    j["plane"] = {{"nx", r.plane->nx},
                  {"ny", r.plane->ny},
                  {"offset", r.plane->offset},
                  {"cost", r.plane->cost},
                  {"seam_mean", r.plane->seam_mean},
                  {"difference", r.plane->difference},
                  {"length", r.plane->length},
                  {"share", r.plane->share}};
  return j;
}

// Reading: every refusal names the file and the field.
struct Reader {
  const std::string& name;

  [[noreturn]] void fail(const std::string& message) const { throw InputError(name, {}, message); }

  double number(const json& j, const std::string& field, const char* key) const {
    const auto it = j.find(key);
    if (it == j.end() || !it->is_number()) fail("field '" + field + "' is missing or not a number");
    return it->get<double>();
  }
  std::optional<double> optional_number(const json& j, const std::string& field, const char* key) const {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return std::nullopt;
    if (!it->is_number()) fail("field '" + field + "' is not a number");
    return it->get<double>();
  }
  std::string text(const json& j, const char* key) const {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return {};
    if (!it->is_string()) fail(std::string("field '") + key + "' is not a string");
    return it->get<std::string>();
  }
};

void read_layers(const Reader& in, const json& j, PlanDocument& out) {
  const auto it = j.find("layers");
  if (it == j.end() || !it->is_array() || it->empty())
    in.fail("field 'layers' is missing or empty (write plans with `salient plan -o`)");
  double below = 0;
  for (std::size_t i = 0; i < it->size(); ++i) {
    const json& l = (*it)[i];
    const std::string field = "layers[" + std::to_string(i) + "]";
    if (!l.is_object()) in.fail("field '" + field + "' is not an object");
    PlanLayer layer;
    layer.z_top = in.number(l, field + ".z_top", "z_top");
    if (!(layer.z_top > below)) in.fail("field '" + field + ".z_top' does not rise");
    // Optional in files from before version 1's checks; then the layer below's top.
    layer.z_bottom = in.optional_number(l, field + ".z_bottom", "z_bottom").value_or(below);
    layer.height = in.optional_number(l, field + ".height", "height").value_or(layer.z_top - layer.z_bottom);
    layer.saliency = in.optional_number(l, field + ".saliency", "saliency");
    layer.cos = in.optional_number(l, field + ".cos", "cos");
    layer.sm = in.optional_number(l, field + ".sm", "sm");
    below = layer.z_top;
    out.layers.push_back(layer);
  }
}

json times_object(const PlanTimes& t) {
  return {{"plan_s", t.plan_seconds},
          {"fine_layers", t.fine_layers},
          {"fine_s", t.fine_seconds},
          {"default_layer_height", t.default_layer_height},
          {"default_layers", t.default_layers},
          {"default_s", t.default_seconds},
          {"default_rsmd", t.default_rsmd},
          {"saving_vs_fine_s", t.saving_vs_fine()},
          {"saving_vs_fine_percent", t.saving_vs_fine_percent()},
          {"saving_vs_default_s", t.saving_vs_default()},
          {"saving_vs_default_percent", t.saving_vs_default_percent()}};
}

}  // namespace

std::string times_json(const PlanTimes& times, int indent) {
  return text_of(times_object(times), indent);
}

std::string segmentation_json(const SegmentationReport& report, int indent) {
  return text_of(segmentation_object(report), indent);
}

std::string plan_json(const PlanDocument& p, int indent) {
  json layers = json::array();
  for (const PlanLayer& l : p.layers) {
    json layer = {{"z_bottom", l.z_bottom}, {"z_top", l.z_top}, {"height", l.height}};
    if (l.saliency) layer["saliency"] = *l.saliency;
    if (l.cos) layer["cos"] = *l.cos;
    if (l.sm) layer["sm"] = *l.sm;
    layers.push_back(std::move(layer));
  }
  json j = {
      {"format", PlanDocument::format},
      {"version", PlanDocument::version},
      {"model", p.model},
      {"planner", p.planner},
      {"metric", p.metric},
      {"count", p.count()},
      {"E", p.error},
      {"epsilon", or_null(p.epsilon)},
      {"rho", or_null(p.rho)},
      {"requested_layers", p.requested_layers ? json(*p.requested_layers) : json(nullptr)},
      {"rsmd", p.rsmd},
      {"seconds", p.seconds},
      {"height", p.height},
      {"grid", p.grid},
      {"min_layer", p.min_layer},
      {"max_layer", p.max_layer},
      {"fine_layers", p.fine_layers},
      {"coarse_layers", p.coarse_layers},
      {"saving_vs_fine", p.fine_layers > 0 ? 1.0 - static_cast<double>(p.count()) / p.fine_layers : 0.0},
      {"layers", layers},
      {"segmentation", p.segmentation ? segmentation_object(*p.segmentation) : json(nullptr)},
  };
  if (!p.note.empty()) j["note"] = p.note;
  if (!p.objective.empty()) j["objective"] = p.objective;
  if (!p.saliency_method.empty()) j["saliency_method"] = p.saliency_method;
  if (p.times) j["times"] = times_object(*p.times);
  if (!p.trace.empty()) {
    json trace = json::array();
    for (const PlanTraceStep& s : p.trace)
      trace.push_back({{"step", s.step}, {"layers", s.layers}, {"E", s.error}});
    j["trace"] = trace;
  }
  return text_of(j, indent);
}

PlanDocument read_plan_json(std::string_view text, const std::string& name) {
  const Reader in{name};
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(name, InputLocation::at_byte(e.byte), "not valid JSON");
  }
  if (!j.is_object()) in.fail("is not a plan (a JSON object with \"format\": \"salient-plan\")");
  if (const auto f = j.find("format"); f != j.end()) {
    if (!f->is_string() || f->get<std::string>() != PlanDocument::format)
      in.fail("is not a plan: field 'format' is " + f->dump() + ", not \"salient-plan\"");
    const auto v = j.find("version");
    if (v == j.end() || !v->is_number_integer() || v->get<long long>() < 1)
      in.fail("field 'version' is missing or not a version number");
    if (v->get<long long>() > PlanDocument::version)
      in.fail("is a salient-plan of version " + v->dump() + "; this salient reads up to version " +
              std::to_string(PlanDocument::version));
  } else if (const auto l = j.find("layers"); l == j.end() || !l->is_array()) {
    // Before version 1 only `salient plan -o` wrote layers; `plan --segment -o` and the daemon
    // wrote other shapes, which had no format field either.
    in.fail(
        "has no field 'format': not a salient-plan (a plan from before version 1 is read only "
        "when `salient plan -o` wrote it; make this one again)");
  }
  PlanDocument out;
  read_layers(in, j, out);
  out.model = in.text(j, "model");
  out.planner = in.text(j, "planner");
  out.metric = in.text(j, "metric");
  out.height = in.optional_number(j, "height", "height").value_or(out.layers.back().z_top);
  out.grid = in.optional_number(j, "grid", "grid").value_or(0);
  out.min_layer = in.optional_number(j, "min_layer", "min_layer").value_or(0);
  out.max_layer = in.optional_number(j, "max_layer", "max_layer").value_or(0);
  out.fine_layers = static_cast<int>(in.optional_number(j, "fine_layers", "fine_layers").value_or(0));
  out.coarse_layers = static_cast<int>(in.optional_number(j, "coarse_layers", "coarse_layers").value_or(0));
  out.error = in.optional_number(j, "E", "E").value_or(0);
  out.rsmd = in.optional_number(j, "rsmd", "rsmd").value_or(0);
  out.epsilon = in.optional_number(j, "epsilon", "epsilon");
  out.rho = in.optional_number(j, "rho", "rho");
  if (const auto n = in.optional_number(j, "requested_layers", "requested_layers")) out.requested_layers = *n;
  out.seconds = in.optional_number(j, "seconds", "seconds").value_or(0);
  out.note = in.text(j, "note");
  out.objective = in.text(j, "objective");
  out.saliency_method = in.text(j, "saliency_method");
  if (const auto t = j.find("times"); t != j.end() && t->is_object()) {
    PlanTimes times;
    const auto number = [&](const char* key) {
      return in.optional_number(*t, std::string("times.") + key, key).value_or(0);
    };
    times.plan_seconds = number("plan_s");
    times.fine_layers = static_cast<int>(number("fine_layers"));
    times.fine_seconds = number("fine_s");
    times.default_layer_height = number("default_layer_height");
    times.default_layers = static_cast<int>(number("default_layers"));
    times.default_seconds = number("default_s");
    times.default_rsmd = number("default_rsmd");
    out.times = times;
  }
  if (const auto c = j.find("count");
      c != j.end() && c->is_number_integer() && c->get<long long>() != out.count())
    in.fail("field 'count' is " + c->dump() + " but 'layers' has " + std::to_string(out.count()));
  return out;
}

}  // namespace salient::core
