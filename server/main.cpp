// salientd: the salient daemon. Without --config it runs on the embedded defaults: data in
// ./var, loopback only. SIGINT/SIGTERM stop it gracefully: no new connections, responses in
// flight finished, running jobs interrupted and left to be re-queued at the next start.
#include <signal.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>

#include "core/common/input_error.hpp"
#include "server/api/api_key.hpp"
#include "server/api/app_key_requests.hpp"
#include "server/api/octoprint_json.hpp"
#include "server/api/printer_forwarding.hpp"
#include "server/api/printer_json.hpp"
#include "server/api/push_hub.hpp"
#include "server/api/routes.hpp"
#include "server/api/sessions.hpp"
#include "server/build_info.hpp"
#include "server/common/json_text.hpp"
#include "server/config/daemon_config.hpp"
#include "server/events/event_hub.hpp"
#include "server/events/event_relay.hpp"
#include "server/http/http_server.hpp"
#include "server/jobs/job_service.hpp"
#include "server/metrics/metrics.hpp"
#include "server/printers/node_presence.hpp"
#include "server/printers/printer_service.hpp"
#include "server/service/systemd_notify.hpp"
#include "server/service/zeroconf.hpp"
#include "server/store/backup.hpp"
#include "server/store/data_dir_lock.hpp"
#include "server/store/farm_store.hpp"
#include "server/store/store.hpp"

namespace {

// A stop signal that reached a thread other than the watcher (see main), and where to send it.
std::atomic<int> g_stop_signal{0};
std::atomic<bool> g_watcher_ready{false};
pthread_t g_watcher{};

void forward_stop_signal(int sig) {
  g_stop_signal.store(sig);
  if (g_watcher_ready.load()) pthread_kill(g_watcher, sig);
}

using namespace salient::server;

// One log line: outside bytes in it (an error echoing a request, a printer's reply) are cut to a
// bounded length and control bytes made visible, so no request can flood or forge the log.
void log_line(const std::string& text) {
  constexpr std::size_t kMax = 2048;
  std::string clean;
  clean.reserve(std::min(text.size(), kMax) + 16);
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    clean += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  if (text.size() > kMax) clean += "… (" + std::to_string(text.size()) + " bytes)";
  static const bool journal = stderr_is_journal();  // the journal stamps lines itself
  if (journal) {
    std::fprintf(stderr, "%s\n", clean.c_str());
    return;
  }
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  std::fprintf(stderr, "%s %s\n", stamp, clean.c_str());
}

// More descriptors when the hard limit allows: each connection, print and store file takes one.
void raise_descriptor_limit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur >= limit.rlim_max) return;
  limit.rlim_cur = std::min<rlim_t>(limit.rlim_max, 65536);
  setrlimit(RLIMIT_NOFILE, &limit);
}

// With a PostgreSQL store: the relay that carries the events between the nodes, started. A job
// that finished on another node starts the prints here that wait for it (this node's own jobs do
// that from JobService's callback, hence `local` is skipped). With SQLite: none, as before.
std::unique_ptr<EventRelay> start_event_relay(Store& store, EventHub& hub, PrinterService& printers,
                                              const std::string& node) {
  if (store.database_url().dialect != Dialect::postgresql) return nullptr;
  EventRelayOptions options;
  options.node = node;
  auto relay = std::make_unique<EventRelay>(
      store.database_url(), hub, [&store]() -> Database& { return store.db(); }, options, log_line);
  relay->on_event([&printers](const RelayedEvent& e) {
    if (!e.local)
      if (const auto job = finished_job(e)) printers.job_finished(*job);
  });
  relay->start();
  log_line("events: relayed between nodes through PostgreSQL (LISTEN/NOTIFY), node=" + node);
  return relay;
}

int serve(const std::string& config_path, const std::string& data, const std::string& listen,
          const std::string& database) {
  DaemonConfig config = config_path.empty() ? default_daemon_config() : load_daemon_config(config_path);
  if (!data.empty()) config.data_dir = data;
  if (!database.empty()) config.store_url = database;
  if (!listen.empty()) config.listen = listen;
  if (config.node.id.empty()) config.node.id = default_node_id();
  const std::size_t colon = config.listen.rfind(':');
  if (colon == std::string::npos)
    throw salient::core::InputError("--listen", {}, "expected ADDRESS:PORT, got '" + config.listen + "'");
  HttpServerOptions http;
  http.address = config.listen.substr(0, colon);
  const std::string port_text = config.listen.substr(colon + 1);
  if (port_text.empty() || port_text.size() > 5 ||
      port_text.find_first_not_of("0123456789") != std::string::npos || std::stoi(port_text) > 65535)
    throw salient::core::InputError("--listen", {}, "'" + port_text + "' is not a port (0 to 65535)");
  http.port = static_cast<unsigned short>(std::stoi(port_text));
  http.body_limit = config.max_upload_bytes;
  http.timeout = std::chrono::seconds(std::max(1L, static_cast<long>(config.request_timeout_seconds)));
  http.max_connections = static_cast<std::size_t>(config.max_connections);
  http.max_connections_per_address = static_cast<std::size_t>(config.max_connections_per_address);
  http.max_bodies_in_flight = config.max_bodies_in_flight_bytes;
  http.log = log_line;
  Metrics metrics;
  http.trusted_proxies = TrustedProxies(config.trusted_proxies);
  http.base_path = config.base_path;
  http.on_response = [&metrics](const std::string& method, const std::string& route, int status,
                                double seconds, const std::string& client) {
    metrics.http_response(method, route, status, seconds);
    log_line("http method=" + method + " route=" + route + " status=" + std::to_string(status) +
             " ms=" + std::to_string(static_cast<int>(seconds * 1000)) + " client=" + client);
  };

  // OpenBLAS starts its thread pool when it is loaded, before these lines can block the signals
  // for it, so a SIGINT/SIGTERM may land on one of its threads: this handler hands it on to the
  // watcher (or leaves it for the watcher to find, if it is not running yet).
  struct sigaction forward {};
  forward.sa_handler = forward_stop_signal;
  sigemptyset(&forward.sa_mask);
  sigaction(SIGINT, &forward, nullptr);
  sigaction(SIGTERM, &forward, nullptr);
  // Signals go to the watcher thread only. SIGUSR2 is our own: it wakes the watcher when the
  // server ends for another reason, and is never logged as a stop request.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGUSR2);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  raise_descriptor_limit();
  const DataDirLock lock(config.data_dir);  // before Store: a second daemon must not clear our tmp/
  Store store(config.data_dir,
              config.store_url.empty() ? std::nullopt : std::optional(DatabaseUrl::parse(config.store_url)),
              config.store_files);
  const ApiKey key = ensure_api_key(store);
  if (key.created)
    log_line("api key (shown once; also in " + (store.data_dir() / "api-key").string() + "): " + key.key);
  Sessions sessions(store);  // before the keys, whose refresher closes sessions until it stops
  ApiKeys keys(store);
  EventHub hub;
  std::unique_ptr<EventRelay> relay;  // PostgreSQL only: set once the printers exist
  OctoState octo;
  // A revoked key ends the sessions opened with it (the push socket then asks to log in again).
  keys.on_revoked([&sessions](long long id) { sessions.close_key(id); });
  // In a farm another node may make or revoke a key: every node reads them again 4 times a second.
  if (store.database_url().dialect == Dialect::postgresql)
    keys.start_refresh(std::chrono::milliseconds(250), log_line);
  PushHub push(sessions, store, octo,
               log_line);  // OctoPrint's push socket: sees the printers through their hooks
  // A farm (several nodes on one PostgreSQL): this node's printers are registered for the others
  // (NodePresence), and requests for theirs are carried to them (PrinterFarm, and the executor).
  const bool farm = store.database_url().dialect == Dialect::postgresql;
  const NodeRoles& roles = config.node.roles;
  DaemonConfig printers_config = config;
  if (!roles.printers) printers_config.printers.clear();  // another node drives them
  if (farm) {  // a printer id another live node holds: refused before anything of it is touched
    std::vector<std::string> ids;
    for (const PrinterConfig& p : printers_config.printers) ids.push_back(p.id);
    FarmStore farm_store(store.db());
    farm_store.check_unclaimed(config.node.id, ids, farm_store.clock() - config.node.lease_seconds);
  }
  NodePresence* presence_hook = nullptr;  // set before any printer starts
  PrinterEvents printer_events = push.hooks(printer_event_publisher(hub));
  printer_events.changed = [&presence_hook, publish = std::move(printer_events.changed)](const Printer& p,
                                                                                         bool progress) {
    if (publish) publish(p, progress);
    if (presence_hook) presence_hook->changed(p);
  };
  PrinterService printers(printers_config, store, std::move(printer_events));
  push.attach(printers);
  NodePresence presence(
      store, {config.node.id, role_list(roles), std::string(version()), config.node.lease_seconds}, &printers,
      [](const Printer& p) { return json_text(printer_status_json(p.status())); });
  // A request for another node's printer holds an HTTP thread while it waits for the answer: a
  // farm's API node gets more of them, and at most all but two wait at once.
  if (farm) http.threads = std::max(http.threads, 8);
  PrinterFarm printer_farm(
      store, {config.node.id, config.node.lease_seconds, 10, config.max_json_bytes, http.threads - 2});
  if (farm)
    printers.set_farm_printers(
        [&printer_farm](const std::string& id) { return printer_farm.other(id).has_value(); });
  if (farm)
    printers.set_farm_profiles(
        [&printer_farm](const std::string& profile) { return printer_farm.profile_live(profile); });
  hub.set_snapshot(event_snapshots(store, printers, farm ? &printer_farm : nullptr));
  // On PostgreSQL the events go through the database to every node's subscribers (and this one's).
  // Declared before the printers, which publish into it until they are gone; stopped before them,
  // since it calls into them (RelayStop, also when an exception unwinds).
  relay = start_event_relay(store, hub, printers, config.node.id);
  struct RelayStop {
    EventRelay* relay;
    ~RelayStop() {
      if (relay) relay->stop();
    }
  } const relay_stop{relay.get()};
  const auto publish_job = job_event_publisher(hub);
  JobService jobs(store, job_service_options(config), [&](const Job& j) {
    publish_job(j);
    if (finished(j.state)) printers.job_finished(j.id);  // a print waiting for it
    if (finished(j.state) && j.started_at && j.finished_at)
      metrics.job_finished(std::string(to_string(j.state)), *j.finished_at - *j.started_at);
    if (finished(j.state) || j.state == JobState::queued)
      log_line("job id=" + j.id + " state=" + std::string(to_string(j.state)) +
               (j.error ? " error=\"" + *j.error + "\"" : ""));
  });
  Router router;
  router.set_authenticator([&keys](const HttpRequest& r) { return keys.authenticate(r); });
  router.set_exception_mapper(
      [](const std::exception& e, const std::string& route) -> std::optional<HttpResponse> {
        log_line("http error route=" + route + " " + e.what());
        if (const auto* s = dynamic_cast<const StoreError*>(&e); s && s->disk_full())
          return error_response(
              507, "insufficient_storage",
              "the server's disk is full: nothing was stored; try again when space has been freed");
        return std::nullopt;
      });
  add_system_routes(router, store, config.node, log_line);
  add_job_routes(router, store, jobs, printers, config);
  add_printer_routes(router, printers, store, config, farm ? &printer_farm : nullptr);
  add_node_routes(router, store, printers, config);
  add_octoprint_routes(router, store, printers, config, octo, sessions, hub);
  AppKeyRequests app_key_requests(store);
  add_auth_routes(router, keys, sessions, app_key_requests);
  add_metrics_route(router, metrics, store, printers, hub, jobs.saliency_cache(), config.node, relay.get());
  add_event_route(router);
  add_sockjs_routes(router);
  add_web_routes(router, config);
  http.websockets["/api/v1/events"] = events_endpoint(hub, keys);
  http.websockets["/sockjs/websocket"] = push.acceptor();
  http.websockets["/sockjs/*"] = push.sockjs_acceptor();
  PrinterRequestExecutor executor(store, router, config.node.id);
  if (farm) {
    // Before any printer starts: a printer id another live node holds stops this one here.
    presence.start([&printers] { printers.farm_tick(); });
    presence_hook = &presence;
    executor.start();
  }
  // A node without the api role builds the router (the executor runs requests through it) but
  // serves only what operations need of every node: /healthz and /metrics (keyed, as everywhere).
  Router ops;
  HttpServerOptions ops_http = http;
  if (!roles.api) {
    ops.set_authenticator([&keys](const HttpRequest& r) { return keys.authenticate(r); });
    add_system_routes(ops, store, config.node, log_line);
    add_metrics_route(ops, metrics, store, printers, hub, jobs.saliency_cache(), config.node, relay.get());
    ops_http.websockets.clear();
  }
  auto server = std::make_unique<HttpServer>(roles.api ? http : ops_http, roles.api ? router : ops);
  const unsigned short port = server->start();
  jobs.start();
  printers.start();
  const std::string where = "listening on http://" + http.address + ":" + std::to_string(port) +
                            (roles.api ? "" : " (/healthz and /metrics only: no api role)");
  log_line("salientd " + std::string(version()) + " " + where + " node=" + config.node.id + " roles=" +
           role_list(roles) + " data=" + config.data_dir + " database=" + store.database_url().redacted());
  notify_ready("listening on " + http.address + ":" + std::to_string(port));
  std::unique_ptr<ZeroconfAnnouncer> zeroconf;
  if (config.zeroconf && roles.api) zeroconf = announce_octoprint(config.zeroconf_name, port, log_line);
  std::atomic<bool> asked{false};
  std::thread watcher([&] {
    g_watcher = pthread_self();
    g_watcher_ready = true;
    int sig = g_stop_signal.load();
    if (sig == 0) sigwait(&signals, &sig);
    if (sig == SIGUSR2) return;
    asked = true;
    notify_stopping();
    log_line(std::string("stopping (") + (sig == SIGINT ? "SIGINT" : "SIGTERM") + ")");
    server->stop();
  });
  server->run();
  // run() returns after stop(), or (a bug) when nothing is left to serve: never exit silently.
  if (!asked) log_line("error: the HTTP server stopped serving without being asked to; stopping");
  jobs.stop(std::chrono::milliseconds(0));  // running jobs are told to stop, not waited for yet
  push.stop();                              // its thread reads the printers: it ends before they do
  executor.stop();
  presence.stop();
  printers.stop();           // a running print is interrupted (heaters off) and can be resumed
  if (relay) relay->stop();  // sends what the printers said last; no more calls into them
  if (!jobs.stop(std::chrono::seconds(1))) {
    // A job inside one long solve has not seen its cancel yet. Its row says "running", so it is
    // re-queued at the next start, as after a crash: nothing to wait for.
    log_line("stopped (a slicing job was still computing: it will be re-queued at the next start)");
    std::fflush(stderr);
    std::_Exit(asked ? 0 : 1);
  }
  if (!asked) pthread_kill(watcher.native_handle(), SIGUSR2);
  watcher.join();
  log_line("stopped");
  return asked ? 0 : 1;
}

// The data directory `backup` and `restore` work on: --data, else the config's.
std::string data_dir_of(const std::string& config_path, const std::string& data) {
  if (!data.empty()) return data;
  return (config_path.empty() ? default_daemon_config() : load_daemon_config(config_path)).data_dir;
}

int backup(const std::string& data_dir, const std::string& dest) {
  const BackupSummary s = backup_data_dir(data_dir, dest);
  std::printf("backup %s: schema %d, %zu stored files (%ju bytes), %d database snapshot(s)\n", dest.c_str(),
              s.schema_version, s.files, static_cast<std::uintmax_t>(s.bytes), s.snapshots);
  return 0;
}

int restore(const std::string& src, const std::string& data_dir, bool force) {
  const BackupSummary s = restore_data_dir(src, data_dir, force);
  std::printf("restored %s into %s: schema %d, %zu stored files (%ju bytes), all verified\n", src.c_str(),
              data_dir.c_str(), s.schema_version, s.files, static_cast<std::uintmax_t>(s.bytes));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"salientd: the salient daemon (REST API, job queue, printers)"};
  app.set_version_flag("--version", "salientd " + std::string(version()));
  std::string config, data, listen, database;
  app.add_option("--config", config,
                 "TOML configuration (default: the embedded defaults, see config/salientd.toml)");
  app.add_option("--data", data, "Data directory: database, stored files, API key (default: var)");
  app.add_option("--database", database,
                 "Store: a SQLite path, sqlite:PATH or postgresql://USER@HOST/DB (default: DATA/salient.db)");
  app.add_option("--listen", listen, "ADDRESS:PORT to serve (default: 127.0.0.1:8080)");
  std::string dest, src;
  bool force = false;
  CLI::App* backup_cmd = app.add_subcommand(
      "backup",
      "Copy the data directory (database and stored files) to DEST, a new directory; the daemon may run");
  backup_cmd->add_option("DEST", dest, "The backup to write (must not exist)")->required();
  backup_cmd->fallthrough();
  CLI::App* restore_cmd = app.add_subcommand(
      "restore", "Verify the backup SRC, then install it as the data directory (the daemon stopped)");
  restore_cmd->add_option("SRC", src, "A directory written by `salientd backup`")->required();
  restore_cmd->add_flag("--force", force, "Replace the data directory's contents if it is not empty");
  restore_cmd->fallthrough();
  app.require_subcommand(0, 1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (backup_cmd->parsed() || restore_cmd->parsed()) {
      const DaemonConfig c = config.empty() ? default_daemon_config() : load_daemon_config(config);
      if (!database.empty() || !c.store_url.empty())
        if (DatabaseUrl::parse(database.empty() ? c.store_url : database).dialect == Dialect::postgresql)
          throw salient::core::InputError("--database", {},
                                          "the store is PostgreSQL: back it up with pg_dump and restore with "
                                          "pg_restore (README, \"Farm\")");
    }
    if (backup_cmd->parsed()) return backup(data_dir_of(config, data), dest);
    if (restore_cmd->parsed()) return restore(src, data_dir_of(config, data), force);
    return serve(config, data, listen, database);
  } catch (const salient::core::InputError& e) {
    std::fprintf(stderr, "salientd: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "salientd: error: %s\n", e.what());
    return 1;
  }
}
