// DaemonConfig: salientd's settings, typed and checked when it starts. Without a file the
// embedded defaults apply: data under ./var, loopback only, one simulated printer "sim".
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "server/config/printer_kind.hpp"

namespace salient::server {

// What a protocol implies unless the config says otherwise: the line rate, and salient-sim's
// arguments for kind = sim (Marlin 2 features on; both 20× faster than real time).
unsigned default_baud(PrinterProtocol protocol);
std::string default_sim_args(PrinterProtocol protocol);

struct PrinterConfig {
  std::string id;
  PrinterKind kind = PrinterKind::sim;
  std::string port;  // serial: device path; tcp: HOST:PORT
  // The profile's flavour decides the protocol unless it is given: Sailfish's → s3g.
  PrinterProtocol protocol = PrinterProtocol::marlin;
  unsigned baud = default_baud(PrinterProtocol::marlin);
  std::string profile = "generic-i3";  // printer profile for slicing (built-in id or .toml path)
  std::string sim_args = default_sim_args(PrinterProtocol::marlin);
  std::string machine = "r2x";  // s3g: the machine definition (steps/mm, feed limits) of the x3g
  bool autoconnect = true;      // connect when the daemon starts
  // Start the next queued print as soon as one ends, without waiting for POST …/queue/next:
  // for printers that clear their own bed (an auto-eject, a belt).
  bool auto_start = false;
};

inline PrinterConfig sim_printer() {
  PrinterConfig p;
  p.id = "sim";
  return p;
}

// [node]: this salientd in a farm of several on one PostgreSQL. Roles: "api" serves HTTP and
// WebSockets, "slicer" claims slicing jobs, "printers" drives the printers configured here. One
// node on SQLite has them all.
struct NodeRoles {
  bool api = true;
  bool slicer = true;
  bool printers = true;
};

// The roles' names in order ("api", "slicer", "printers"), as config, logs and the API spell them.
std::vector<std::string> role_names(const NodeRoles& roles);
std::string role_list(const NodeRoles& roles);  // the same, comma-separated: "api,slicer"

struct NodeConfig {
  std::string id;  // unique in the farm; empty: the host name
  NodeRoles roles;
  // A slicer holds a claimed job by renewing its lease; a node that has not renewed within this
  // is taken as dead: its jobs go back to the queue, its printers show offline.
  double lease_seconds = 15;
  int max_attempts = 3;  // a job whose slicer died this many times fails instead (the reasons kept)
};

// The host name, as a node id ("local" when it has none).
std::string default_node_id();

struct DaemonConfig {
  std::string listen = "127.0.0.1:8080";
  std::string data_dir = "var";
  // [store] url (or salientd --database): the database, a path, sqlite:PATH or postgresql://…;
  // empty: SQLite in data_dir. With PostgreSQL the files are kept in it too (data_dir holds this
  // node's cache of them) unless store_files names a directory the nodes share ([store] files).
  std::string store_url;
  std::string store_files;
  std::size_t max_upload_bytes = 64u << 20;
  std::size_t max_json_bytes = 256u << 10;
  int max_json_depth = 32;
  double request_timeout_seconds = 30;  // with no progress: a slow upload that keeps sending goes on
  int max_connections = 512;            // HTTP and WebSocket at once; more are answered 503 and closed
  int max_connections_per_address = 64;
  std::size_t max_bodies_in_flight_bytes = 256u << 20;  // request bodies being read at once (503 beyond)
  // Behind a reverse proxy: the proxies whose X-Forwarded-For/-Proto/-Host/-Prefix are believed
  // (addresses or networks), and the path prefix salientd is served under when the proxy does
  // not send X-Forwarded-Prefix ("" : the root). See deploy/nginx/salient.conf.
  std::vector<std::string> trusted_proxies;
  std::string base_path;
  int workers = 1;
  int queue_limit = 32;
  double job_time_limit_minutes = 30;  // [jobs] time_limit_minutes: a slice running longer fails
  // Where the web page's JavaScript libraries are read from (Debian's libjs-three and
  // libjs-chart.js install under it), served at /vendor/three/… and /vendor/chart.js/….
  std::string web_vendor_dir = "/usr/share/javascript";
  // [zeroconf]: announce salientd as OctoPrint does (_octoprint._tcp, _http._tcp) through Avahi,
  // so that Cura and phone apps find it. Off by default: a daemon on loopback has no one to tell.
  bool zeroconf = false;
  std::string zeroconf_name;  // empty: "salient on HOSTNAME"
  NodeConfig node;
  std::vector<PrinterConfig> printers = {sim_printer()};
};

DaemonConfig default_daemon_config();
// Throws InputError "FILE:LINE: …" naming the key that is unknown or wrong.
DaemonConfig parse_daemon_config(std::string_view text, const std::string& source);
DaemonConfig load_daemon_config(const std::string& path);

}  // namespace salient::server
