// /api/v1/nodes: the nodes of a farm (several salientd on one PostgreSQL), whether each is alive
// on the database's clock, and forgetting a retired one. A single node (SQLite) lists itself.
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "server/api/api_json.hpp"
#include "server/api/routes.hpp"
#include "server/build_info.hpp"
#include "server/store/farm_store.hpp"

namespace salient::server {
namespace {

using nlohmann::json;

json role_list(const std::string& roles) {  // "api,slicer" as ["api", "slicer"]
  json out = json::array();
  for (std::size_t at = 0; at <= roles.size();) {
    const std::size_t comma = std::min(roles.find(',', at), roles.size());
    if (comma > at) out.push_back(roles.substr(at, comma - at));
    at = comma + 1;
  }
  return out;
}

json node_json(const FarmNode& n, const std::vector<std::string>& printers, double lease_seconds,
               const std::string& self) {
  return {{"id", n.id},
          {"roles", role_list(n.roles)},
          {"version", n.version},
          {"started_at", n.started_at},
          {"heartbeat_age", std::round(n.heartbeat_age * 1000) / 1000},
          {"live", n.heartbeat_age <= lease_seconds},
          {"self", n.id == self},
          {"printers", printers}};
}

}  // namespace

void add_node_routes(Router& router, Store& store, PrinterService& printers, const DaemonConfig& config) {
  const bool farm = store.database_url().dialect == Dialect::postgresql;
  router.add("GET", "/api/v1/nodes", Access::viewer,
             [&store, &printers, &config, farm](const HttpRequest&, const PathParams&) {
               const NodeConfig& self = config.node;
               json nodes = json::array();
               if (!farm) {  // no farm: this node, as it runs
                 std::vector<std::string> ids;
                 for (const auto& p : printers.all()) ids.push_back(p->id());
                 nodes.push_back(node_json({self.id, "", std::string(version()), 0, 0, 0}, ids,
                                           self.lease_seconds, self.id));
                 nodes.back()["roles"] = role_names(self.roles);
                 nodes.back()["started_at"] = nullptr;
               } else {
                 FarmStore farm_store(store.db());
                 std::map<std::string, std::vector<std::string>> by_node;
                 for (const FarmPrinter& p : farm_store.printers()) by_node[p.node].push_back(p.id);
                 for (const FarmNode& n : farm_store.nodes())
                   nodes.push_back(node_json(n, by_node[n.id], self.lease_seconds, self.id));
               }
               return json_response(200, {{"nodes", nodes}, {"lease_seconds", self.lease_seconds}});
             });
  // A retired host's node stays listed dead, with its printers offline, until it is forgotten.
  router.add("DELETE", "/api/v1/nodes/{id}", Access::admin,
             [&store, &config, farm](const HttpRequest&, const PathParams& p) {
               const std::string& id = p.at("id");
               if (id == config.node.id)
                 throw ApiError(409, "conflict",
                                "node '" + id + "' is this node: stop it, then forget it from another");
               if (!farm)
                 throw ApiError(
                     404, "not_found",
                     "no node '" + id.substr(0, 80) + "': this salientd is a single node (SQLite store)");
               switch (FarmStore(store.db()).forget(id, config.node.lease_seconds)) {
                 case FarmStore::Forget::unknown:
                   throw ApiError(404, "not_found", "no node '" + id.substr(0, 80) + "' in the farm");
                 case FarmStore::Forget::alive:
                   throw ApiError(409, "conflict",
                                  "node '" + id + "' is alive (its heartbeat is younger than " +
                                      std::to_string(static_cast<int>(config.node.lease_seconds)) +
                                      " s): stop it before forgetting it");
                 case FarmStore::Forget::forgotten:
                   break;
               }
               return HttpResponse::text(204, "");
             });
}

}  // namespace salient::server
