// salientd: the salient daemon. Without --config it runs on the embedded defaults: data in
// ./var, loopback only. SIGINT/SIGTERM stop it gracefully: no new connections, responses in
// flight finished, running jobs interrupted and left to be re-queued at the next start.
#include <signal.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <thread>

#include "core/common/input_error.hpp"
#include "server/api/api_key.hpp"
#include "server/api/routes.hpp"
#include "server/build_info.hpp"
#include "server/config/daemon_config.hpp"
#include "server/http/http_server.hpp"
#include "server/events/event_hub.hpp"
#include "server/jobs/job_service.hpp"
#include "server/metrics/metrics.hpp"
#include "server/printers/printer_service.hpp"
#include "server/store/store.hpp"

namespace {

using namespace salient::server;

void log_line(const std::string& text) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  std::fprintf(stderr, "%s %s\n", stamp, text.c_str());
}

int serve(const std::string& config_path, const std::string& data, const std::string& listen) {
  DaemonConfig config = config_path.empty() ? default_daemon_config() : load_daemon_config(config_path);
  if (!data.empty()) config.data_dir = data;
  if (!listen.empty()) config.listen = listen;
  const std::size_t colon = config.listen.rfind(':');
  if (colon == std::string::npos) throw salient::core::InputError("--listen", {}, "expected ADDRESS:PORT, got '" + config.listen + "'");
  HttpServerOptions http;
  http.address = config.listen.substr(0, colon);
  try {
    http.port = static_cast<unsigned short>(std::stoi(config.listen.substr(colon + 1)));
  } catch (const std::exception&) {
    throw salient::core::InputError("--listen", {}, "'" + config.listen.substr(colon + 1) + "' is not a port");
  }
  http.body_limit = config.max_upload_bytes;
  http.timeout = std::chrono::seconds(static_cast<long>(config.request_timeout_seconds));
  Metrics metrics;
  http.on_response = [&metrics](const std::string& method, const std::string& route, int status, double seconds) {
    metrics.http_response(method, route, status, seconds);
    log_line("http method=" + method + " route=" + route + " status=" + std::to_string(status) +
             " ms=" + std::to_string(static_cast<int>(seconds * 1000)));
  };

  // Signals go to the watcher thread only.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  Store store(config.data_dir);
  const ApiKey key = ensure_api_key(store);
  if (key.created)
    log_line("api key (shown once; also in " + (store.data_dir() / "api-key").string() + "): " + key.key);
  const ApiKeys keys(store);
  EventHub hub;
  PrinterService printers(config, store, hub);
  hub.set_snapshot(event_snapshots(store, printers));
  const auto publish_job = job_event_publisher(hub);
  JobService jobs(store, {config.workers, config.queue_limit, static_cast<std::size_t>(config.max_json_depth)},
                  [&](const Job& j) {
                    publish_job(j);
                    if (finished(j.state) && j.started_at && j.finished_at)
                      metrics.job_finished(std::string(to_string(j.state)), *j.finished_at - *j.started_at);
                    if (finished(j.state) || j.state == JobState::queued)
                      log_line("job id=" + j.id + " state=" + std::string(to_string(j.state)) +
                               (j.error ? " error=\"" + *j.error + "\"" : ""));
                  });
  Router router;
  router.set_authenticator([&keys](const HttpRequest& r) { return keys.valid(r); });
  add_system_routes(router);
  add_job_routes(router, store, jobs, config);
  add_printer_routes(router, printers, store, config);
  add_octoprint_routes(router, store, printers, config);
  add_metrics_route(router, metrics, store, printers, hub);
  add_event_route(router);
  http.websocket = events_endpoint(hub, keys);
  HttpServer server(http, router);
  const unsigned short port = server.start();
  jobs.start();
  printers.start();
  log_line("salientd " + std::string(version()) + " listening on http://" + http.address + ":" + std::to_string(port) +
           " data=" + config.data_dir);
  std::thread watcher([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    log_line(std::string("stopping (") + (sig == SIGINT ? "SIGINT" : "SIGTERM") + ")");
    server.stop();
  });
  server.run();
  jobs.stop();
  printers.stop();  // a running print is interrupted (heaters off) and can be resumed
  if (watcher.joinable()) {
    pthread_kill(watcher.native_handle(), SIGTERM);  // in case run() ended without a signal
    watcher.join();
  }
  log_line("stopped");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"salientd: the salient daemon (REST API, job queue, printers)"};
  app.set_version_flag("--version", "salientd " + std::string(version()));
  std::string config, data, listen;
  app.add_option("--config", config, "TOML configuration (default: the embedded defaults, see config/salientd.toml)");
  app.add_option("--data", data, "Data directory: database, stored files, API key (default: var)");
  app.add_option("--listen", listen, "ADDRESS:PORT to serve (default: 127.0.0.1:8080)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return serve(config, data, listen);
  } catch (const salient::core::InputError& e) {
    std::fprintf(stderr, "salientd: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "salientd: error: %s\n", e.what());
    return 1;
  }
}
