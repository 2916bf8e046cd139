// OctoPrint's /api/settings (what Cura, FDM Monster and OctoPod read; the keys they write kept in
// the store across restarts) and /api/system/… (info, and the system commands: none, since
// salientd does not restart or shut down its host — unknown commands are 404, as OctoPrint).
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "server/api/api_json.hpp"
#include "server/api/octoprint_routes.hpp"
#include "server/api/octoprint_settings.hpp"
#include "server/build_info.hpp"
#include "server/common/json_text.hpp"
#include "server/store/settings_store.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

constexpr const char* kSettingsKey = "octoprint";

json default_settings(const OctoContext& ctx) {
  const Printer* p = ctx.printers.first();
  const PrinterConfig c = p ? p->config() : PrinterConfig{};
  return {{"api", {{"enabled", true}, {"allowCrossOrigin", false}}},
          {"appearance",
           {{"name", "salient"},
            {"color", "default"},
            {"colorTransparent", false},
            {"colorIcon", true},
            {"defaultLanguage", "_default"},
            {"showFahrenheitAlso", false},
            {"fuzzyTimes", true},
            {"closeModalsWithClick", true},
            {"showInternalFilename", true}}},
          {"feature",
           {{"sdSupport", false},
            {"temperatureGraph", true},
            {"keyboardControl", true},
            {"pollWatched", false},
            {"modelSizeDetection", true},
            {"printCancelConfirmation", true},
            {"g90InfluencesExtruder", false}}},
          {"folder", {{"uploads", ""}, {"timelapse", ""}, {"watched", ""}}},
          {"gcodeAnalysis", {{"runAt", "idle"}}},
          {"serial",
           {{"port", c.kind == PrinterKind::sim ? "VIRTUAL" : c.port},
            {"baudrate", c.baud},
            {"autoconnect", c.autoconnect},
            {"portOptions", {c.kind == PrinterKind::sim ? "VIRTUAL" : c.port}},
            {"baudrateOptions", {c.baud}}}},
          {"server",
           {{"commands",
             {{"serverRestartCommand", ""}, {"systemRestartCommand", ""}, {"systemShutdownCommand", ""}}},
            {"allowFraming", false},
            {"onlineCheck", {{"enabled", false}}}}},
          {"temperature",
           {{"profiles",
             {{{"name", "ABS"}, {"extruder", 240}, {"bed", 100}, {"chamber", nullptr}},
              {{"name", "PLA"}, {"extruder", 210}, {"bed", 60}, {"chamber", nullptr}}}},
            {"cutoff", 30},
            {"sendAutomatically", false},
            {"sendAutomaticallyAfter", 1}}},
          {"webcam",
           {{"webcamEnabled", false},
            {"timelapseEnabled", false},
            {"streamUrl", ""},
            {"snapshotUrl", ""},
            {"flipH", false},
            {"flipV", false},
            {"rotate90", false}}},
          {"system", {{"actions", json::array()}, {"events", nullptr}}},
          {"terminalFilters", json::array()},
          {"plugins", json::object()}};
}

json stored_overlay(Store& store) {
  const auto text = SettingsStore(store.db()).get(kSettingsKey);
  if (!text) return json::object();
  json overlay = json::parse(*text, nullptr, false);
  return overlay.is_object() ? overlay : json::object();
}

json current_settings(const OctoContext& ctx) {
  json out = default_settings(ctx);
  out.merge_patch(stored_overlay(ctx.store));
  return out;
}

HttpResponse save_settings(const OctoContext& ctx, const HttpRequest& r) {
  const json body = parse_json_body(r, ctx.max_json, ctx.depth);  // 400 unless an object
  const json accepted = accepted_settings(default_settings(ctx), body);
  if (!accepted.empty()) {
    // Read, merge and write under one lock: two clients' changes do not undo each other.
    static std::mutex settings_mutex;
    std::lock_guard lock(settings_mutex);
    json overlay = stored_overlay(ctx.store);
    overlay.merge_patch(accepted);
    SettingsStore(ctx.store.db()).put(kSettingsKey, json_text(overlay), octo_now());
  }
  return json_response(200, current_settings(ctx));
}

json system_info(const HttpRequest& r) {
  const std::string octo(octoprint_version);
  return {{"systeminfo",
           {{"browser.user_agent", r.header("user-agent")},
            {"connectivity.online", false},
            {"env.hardware.cores", std::thread::hardware_concurrency()},
            {"env.os.platform", "linux"},
            {"env.python.version", ""},
            {"octoprint.version", octo},
            {"octoprint.safe_mode", false},
            {"octoprint.last_safe_mode.date", "unknown"},
            {"salientd.version", std::string(version())},
            {"systeminfo.generator", "systemapi"}}}};
}

void known_source(const std::string& source) {
  if (source != "core" && source != "custom")
    throw ApiError(404, "not_found", "unknown command source: " + source);
}

}  // namespace

void add_octoprint_system_routes(Router& router, const OctoContext& ctx) {
  router.add("GET", "/api/settings", Access::key, [ctx](const HttpRequest&, const PathParams&) {
    return json_response(200, current_settings(ctx));
  });
  router.add("POST", "/api/settings", Access::key,
             [ctx](const HttpRequest& r, const PathParams&) { return save_settings(ctx, r); });
  router.add("GET", "/api/system/info", Access::key,
             [](const HttpRequest& r, const PathParams&) { return json_response(200, system_info(r)); });
  router.add("GET", "/api/system/commands", Access::key, [](const HttpRequest&, const PathParams&) {
    return json_response(200, {{"core", json::array()}, {"custom", json::array()}});
  });
  router.add("GET", "/api/system/commands/{source}", Access::key,
             [](const HttpRequest&, const PathParams& p) {
               known_source(p.at("source"));
               return json_response(200, json::array());
             });
  router.add("POST", "/api/system/commands/{source}/{action}", Access::key,
             [](const HttpRequest&, const PathParams& p) -> HttpResponse {
               known_source(p.at("source"));
               throw ApiError(
                   404, "not_found",
                   "no command " + p.at("action").substr(0, 64) + " in " + p.at("source") +
                       ": salientd runs no system commands (it does not restart or shut down its host)");
             });
}

}  // namespace salient::server
