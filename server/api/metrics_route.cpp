// GET /metrics: the daemon's counters, and gauges read at scrape time from the database, the
// printers and the event hub.
#include "server/api/routes.hpp"
#include "server/events/event_relay.hpp"
#include "server/store/job_store.hpp"

namespace salient::server {

void add_metrics_route(Router& router, const Metrics& metrics, Store& store, PrinterService& printers,
                       const EventHub& hub, const core::SaliencyCache& saliency, const NodeConfig& node,
                       const EventRelay* relay) {
  router.add(
      "GET", "/metrics", Access::key,
      [&metrics, &store, &printers, &hub, &saliency, node, relay](const HttpRequest&, const PathParams&) {
        // Which farm node this is (Prometheus' own `instance` label is its address): an info gauge,
        // joined on by queries that need the node.
        const std::string roles = role_list(node.roles);
        std::string out =
            "# HELP salient_node_info This salientd's farm node id and roles.\n# TYPE salient_node_info "
            "gauge\n"
            "salient_node_info{node=\"" +
            prometheus_label(node.id) + "\",roles=\"" + roles + "\"} 1\n";
        out += metrics.render();
        JobStore jobs(store.db());
        out += "# HELP salient_jobs Jobs in the database, by state.\n# TYPE salient_jobs gauge\n";
        for (const auto& [s, name] : job_state_names)  // every state, even with no job in it
          out += "salient_jobs{state=\"" + std::string(name) + "\"} " + std::to_string(jobs.count(s)) + "\n";
        out +=
            "# HELP salient_job_queue_length Jobs waiting for a worker.\n# TYPE salient_job_queue_length "
            "gauge\n";
        out += "salient_job_queue_length " + std::to_string(jobs.count(JobState::queued)) + "\n";
        out +=
            "# HELP salient_print_lines_total G-code commands acknowledged by printers.\n# TYPE "
            "salient_print_lines_total counter\n";
        std::string resent, prints, up;
        for (const auto& p : printers.all()) {
          const PrinterCounters c = p->counters();
          const std::string label = "{printer=\"" + prometheus_label(p->id()) + "\"}";
          out += "salient_print_lines_total" + label + " " + std::to_string(c.lines_sent) + "\n";
          resent += "salient_print_resends_total" + label + " " + std::to_string(c.lines_resent) + "\n";
          prints += "salient_prints_total{printer=\"" + prometheus_label(p->id()) +
                    "\",result=\"finished\"} " + std::to_string(c.prints_finished) + "\n";
          prints += "salient_prints_total{printer=\"" + prometheus_label(p->id()) + "\",result=\"failed\"} " +
                    std::to_string(c.prints_failed) + "\n";
          up += "salient_printer_connected" + label + " " + (connected(p->state()) ? "1" : "0") + "\n";
        }
        out +=
            "# HELP salient_print_resends_total Lines sent again at the printer's request.\n# TYPE "
            "salient_print_resends_total counter\n" +
            resent;
        out +=
            "# HELP salient_prints_total Prints that ended, by result.\n# TYPE salient_prints_total "
            "counter\n" +
            prints;
        out +=
            "# HELP salient_printer_connected 1 when the printer's link is up.\n# TYPE "
            "salient_printer_connected gauge\n" +
            up;
        out +=
            "# HELP salient_event_subscribers WebSocket clients connected to /api/v1/events.\n# TYPE "
            "salient_event_subscribers gauge\n";
        out += "salient_event_subscribers " + std::to_string(hub.subscribers()) + "\n";
        out +=
            "# HELP salient_saliency_cache_hits_total Jobs whose saliency an earlier job had computed.\n"
            "# TYPE salient_saliency_cache_hits_total counter\nsalient_saliency_cache_hits_total " +
            std::to_string(saliency.hits()) + "\n";
        out +=
            "# HELP salient_saliency_cache_misses_total Saliency computed by jobs (uniform is not counted).\n"
            "# TYPE salient_saliency_cache_misses_total counter\nsalient_saliency_cache_misses_total " +
            std::to_string(saliency.misses()) + "\n";
        if (relay) {
          const EventRelayStats s = relay->stats();
          out +=
              "# HELP salient_relay_events_total Events between the farm's nodes through PostgreSQL: sent, "
              "received (every node's), coalesced or dropped under backlog (never a state change), stored "
              "(too large for a NOTIFY).\n# TYPE salient_relay_events_total counter\n";
          for (const auto& [what, n] : {std::pair{"sent", s.sent},
                                        {"received", s.received},
                                        {"coalesced", s.coalesced},
                                        {"dropped", s.dropped},
                                        {"stored", s.stored}})
            out +=
                "salient_relay_events_total{what=\"" + std::string(what) + "\"} " + std::to_string(n) + "\n";
          out +=
              "# HELP salient_relay_reconnects_total Times the relay's listener connected again.\n# TYPE "
              "salient_relay_reconnects_total counter\nsalient_relay_reconnects_total " +
              std::to_string(s.reconnects) + "\n";
        }
        return HttpResponse::text(200, std::move(out), "text/plain; version=0.0.4; charset=utf-8");
      });
}

}  // namespace salient::server
