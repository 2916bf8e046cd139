#include <nlohmann/json.hpp>

#include "server/api/routes.hpp"
#include "server/build_info.hpp"
#include "server/common/json_text.hpp"

namespace salient::server {

void add_system_routes(Router& router) {
  router.add("GET", "/healthz", Access::open, [](const HttpRequest&, const PathParams&) {
    return HttpResponse::text(200, R"({"status":"ok"})", "application/json");
  });
  // OctoPrint's version call: slicers check "api", and that "text" starts with "OctoPrint".
  router.add("GET", "/api/version", Access::open, [](const HttpRequest&, const PathParams&) {
    const std::string v(version()), octo(octoprint_version);
    return HttpResponse::text(
        200,
        json_text(nlohmann::json{{"api", octoprint_api_version},
                                 {"server", octo},
                                 {"text", "OctoPrint " + octo + " (salientd " + v + ")"},
                                 {"salientd", v},
                                 {"salient_api", api_level}}),
        "application/json");
  });
}

}  // namespace salient::server
