// The daemon's endpoints, declared in one place per area.
#pragma once

#include <functional>

#include "server/api/api_key.hpp"
#include "server/config/daemon_config.hpp"
#include "server/events/event_hub.hpp"
#include "server/http/router.hpp"
#include "server/http/websocket_channel.hpp"
#include "server/jobs/job_service.hpp"
#include "server/metrics/metrics.hpp"
#include "server/printers/printer_service.hpp"
#include "server/store/store.hpp"

namespace salient::server {

// /healthz (the node, and its database answering: 503 when it does not, the reason to `log`) and
// /api/version; both open.
void add_system_routes(Router& router, Store& store, const NodeConfig& node,
                       std::function<void(const std::string&)> log = {});
// /api/v1/jobs…: submit (and print once sliced: the `print` field), list, get, cancel/remove,
// artefacts.
void add_job_routes(Router& router, Store& store, JobService& jobs, PrinterService& printers,
                    const DaemonConfig& config);
// /api/v1/printers…: status, connect/disconnect, print, pause/resume/cancel/emergency-stop, command,
// queues; /api/v1/farm/{profile}/…: a profile's farm-wide queue. With a farm (several nodes on
// one PostgreSQL), other nodes' printers are listed too and requests for them carried to their node.
class PrinterFarm;
void add_printer_routes(Router& router, PrinterService& printers, Store& store, const DaemonConfig& config,
                        PrinterFarm* farm = nullptr);
// /api/v1/nodes: the farm's nodes (each with its roles, printers and whether it is alive on the
// database's clock; a single node lists itself), and DELETE …/{id} (admin) to forget a dead one.
void add_node_routes(Router& router, Store& store, PrinterService& printers, const DaemonConfig& config);
struct OctoState;
class Sessions;
// OctoPrint's API as its clients use it: /api/files/local, /api/job, /api/printer, /api/settings,
// /api/login… `octo` (the selected file, analyses) is shared with the push socket; `sessions`
// are what passive logins hand out; changes to files are published on `hub` ("files").
void add_octoprint_routes(Router& router, Store& store, PrinterService& printers, const DaemonConfig& config,
                          OctoState& octo, Sessions& sessions, EventHub& hub);
class AppKeyRequests;
// /api/login (passive), /api/currentuser, /api/v1/keys… (list, create, revoke, app requests and
// their decisions) and OctoPrint's /plugin/appkeys/… (probe, request, poll, decision).
void add_auth_routes(Router& router, ApiKeys& keys, Sessions& sessions, AppKeyRequests& requests);
// The web page (open): / and /web/{file} from the binary, /vendor/{three,chart.js}/… from
// config.web_vendor_dir.
void add_web_routes(Router& router, const DaemonConfig& config);
class EventRelay;
// /metrics (Prometheus text), with this node's id (salient_node_info) and, in a farm, the events
// relayed between nodes (`relay`, may be null).
void add_metrics_route(Router& router, const Metrics& metrics, Store& store, PrinterService& printers,
                       const EventHub& hub, const core::SaliencyCache& saliency, const NodeConfig& node,
                       const EventRelay* relay = nullptr);

// The WebSocket /api/v1/events (keyed; ?topics=a,b subscribes at once), and 426 for a plain GET.
void add_event_route(Router& router);
WebSocketAcceptor events_endpoint(EventHub& hub, ApiKeys& keys);
// What a new subscriber to a topic sees first: the job's or printers' current state.
class PrinterFarm;
// `farm` (a farm's API node): other nodes' printers are in the snapshots too.
SnapshotFn event_snapshots(Store& store, PrinterService& printers, PrinterFarm* farm = nullptr);
// Job changes as "job" events; a change of state or phase is never dropped, progress coalesces.
std::function<void(const Job&)> job_event_publisher(EventHub& hub);
// Printer changes as "printer" events (state always delivered, progress coalesces) and the
// terminal's lines as "terminal" events (best effort, split only while someone watches).
PrinterEvents printer_event_publisher(EventHub& hub);

}  // namespace salient::server
