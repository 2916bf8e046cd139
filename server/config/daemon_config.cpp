#include "server/config/daemon_config.hpp"

#include <fstream>
#include <set>
#include <sstream>

#include "core/common/toml_table_reader.hpp"
#include "server/printers/sim_process.hpp"

namespace salient::server {

using core::InputError;
using core::InputLocation;
using core::TableReader;

DaemonConfig default_daemon_config() {
  return DaemonConfig{};
}

DaemonConfig parse_daemon_config(std::string_view text, const std::string& source) {
  const toml::table root = core::parse_toml(text, source);
  DaemonConfig c;
  TableReader top(root, "", source);
  double upload_mb = double(c.max_upload_bytes) / (1 << 20), json_kb = double(c.max_json_bytes) / (1 << 10);
  double in_flight_mb = double(c.max_bodies_in_flight_bytes) / (1 << 20);
  core::read_section(top, "server", source, [&](TableReader& r) {
    r.text("listen", c.listen);
    r.text("data", c.data_dir);
    r.number("max_upload_mb", upload_mb, 0.001, 65536.0);
    r.number("max_json_kb", json_kb, 1.0, 1048576.0);
    r.integer("max_json_depth", c.max_json_depth, 1, 1000);
    r.number("request_timeout_seconds", c.request_timeout_seconds, 1.0, 86400.0);
    r.integer("max_connections", c.max_connections, 1, 1000000);
    r.integer("max_connections_per_address", c.max_connections_per_address, 1, 1000000);
    r.number("max_bodies_in_flight_mb", in_flight_mb, 0.001, 1048576.0);
  });
  if (!(in_flight_mb >= upload_mb))
    throw InputError(source, {}, "'server.max_bodies_in_flight_mb' must be at least 'server.max_upload_mb'");
  c.max_bodies_in_flight_bytes = static_cast<std::size_t>(in_flight_mb * (1 << 20));
  c.max_upload_bytes = static_cast<std::size_t>(upload_mb * (1 << 20));
  c.max_json_bytes = static_cast<std::size_t>(json_kb * (1 << 10));
  core::read_section(top, "jobs", source, [&](TableReader& r) {
    r.integer("workers", c.workers, 1, 64);
    r.integer("queue_limit", c.queue_limit, 1, 100000);
  });
  if (const toml::array* printers = top.array("printers")) {
    c.printers.clear();
    std::set<std::string> ids;
    for (const toml::node& n : *printers) {
      if (!n.is_table())
        throw InputError(source, InputLocation::at_line(core::line_of(n)),
                         "'printers' entries must be tables");
      PrinterConfig p;
      TableReader r(*n.as_table(), "printers.", source);
      r.text("id", p.id);
      std::string kind(to_string(p.kind)), protocol(to_string(p.protocol));
      r.text("kind", kind);
      r.text("port", p.port);
      r.integer("baud", p.baud, 300, 4000000);
      r.text("protocol", protocol);
      r.text("profile", p.profile);
      r.text("sim_args", p.sim_args);
      r.boolean("autoconnect", p.autoconnect);
      r.reject_unknown();
      const InputLocation at = InputLocation::at_line(core::line_of(n));
      if (p.id.empty() ||
          p.id.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos)
        throw InputError(source, at,
                         "'printers.id' must be lower-case letters, digits, '-' or '_', got '" + p.id + "'");
      if (!ids.insert(p.id).second) throw InputError(source, at, "printer id '" + p.id + "' appears twice");
      if (const auto k = printer_kind_from(kind))
        p.kind = *k;
      else
        throw InputError(source, at, "'printers.kind' must be sim, serial or tcp, got '" + kind + "'");
      if (p.kind != PrinterKind::sim && p.port.empty())
        throw InputError(source, at, "printer '" + p.id + "' needs a 'port'");
      if (p.kind == PrinterKind::sim) {
        try {
          split_args(p.sim_args);  // checked now rather than at the first connect
        } catch (const std::invalid_argument& e) {
          throw InputError(source, at, "'printers.sim_args': " + std::string(e.what()));
        }
      }
      if (const auto pr = printer_protocol_from(protocol))
        p.protocol = *pr;
      else
        throw InputError(source, at, "'printers.protocol' must be marlin (s3g comes later)");
      c.printers.push_back(std::move(p));
    }
  }
  top.reject_unknown();
  return c;
}

DaemonConfig load_daemon_config(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, {}, "cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_daemon_config(text.str(), path);
}

}  // namespace salient::server
