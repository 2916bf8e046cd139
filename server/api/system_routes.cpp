#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "server/api/routes.hpp"
#include "server/build_info.hpp"
#include "server/common/json_text.hpp"

namespace salient::server {

void add_system_routes(Router& router, Store& store, const NodeConfig& node,
                       std::function<void(const std::string&)> log) {
  // For load balancers and `salient doctor`: this node is up when its database answers. Open to
  // all, so the database's error (host names, users) goes to the log, not into the answer.
  router.add("GET", "/healthz", Access::open, [&store, node, log](const HttpRequest&, const PathParams&) {
    nlohmann::json out{{"status", "ok"}, {"node", node.id}, {"roles", role_names(node.roles)}};
    const auto start = std::chrono::steady_clock::now();
    try {
      Database& db = store.db();
      auto q = db.prepare("SELECT 1");
      q.step();
      q.run();
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      out["database"] = {{"kind", db.dialect() == Dialect::postgresql ? "postgresql" : "sqlite"},
                         {"schema", db.schema_version()},
                         {"latest_schema", Database::latest_schema_version()},
                         {"ms", std::round(ms * 1000) / 1000}};
    } catch (const std::exception& e) {
      out["status"] = "unavailable";
      out["database"] = {{"error", "the database does not answer (see salientd's log)"}};
      if (log) log(std::string("healthz: the database does not answer: ") + e.what());
      return HttpResponse::text(503, json_text(out), "application/json");
    }
    return HttpResponse::text(200, json_text(out), "application/json");
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
