#include "server/config/daemon_config.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include "core/common/toml_table_reader.hpp"
#include "core/printer/printer_profile.hpp"
#include "protocol/s3g/machine.hpp"
#include "server/http/client_address.hpp"
#include "server/printers/sim_process.hpp"
#include "server/store/database.hpp"  // DatabaseUrl, StoreError

namespace salient::server {

using core::InputError;
using core::InputLocation;
using core::TableReader;

unsigned default_baud(PrinterProtocol protocol) {
  return protocol == PrinterProtocol::s3g ? 115200 : 250000;
}

std::string default_sim_args(PrinterProtocol protocol) {
  if (protocol == PrinterProtocol::s3g) return "--firmware sailfish --baud 115200 --time-scale 0.05";
  return "--advanced-ok --emergency-parser --autoreport --time-scale 0.05";
}

namespace {

// The protocol a profile's G-code is written for: Sailfish's flavour is printed over s3g.
PrinterProtocol protocol_of_profile(const std::string& profile) {
  std::optional<core::PrinterProfile> p = core::builtin_printer(profile);
  std::error_code ec;
  if (!p && std::filesystem::is_regular_file(profile, ec)) {
    try {
      p = core::load_printer_profile(profile);
    } catch (const InputError&) {
      // Reported where the profile is used (slicing), with its own line numbers.
    }
  }
  return p && p->flavor == core::GcodeFlavor::sailfish ? PrinterProtocol::s3g : PrinterProtocol::marlin;
}

void read_proxy_settings(TableReader& r, DaemonConfig& c, const std::string& source) {
  if (const toml::array* proxies = r.array("trusted_proxies", "an array of addresses or networks")) {
    for (const toml::node& n : *proxies) {
      const InputLocation at = InputLocation::at_line(core::line_of(n));
      if (!n.is_string())
        throw InputError(source, at, "'server.trusted_proxies' holds addresses as strings (\"127.0.0.1\")");
      c.trusted_proxies.push_back(n.as_string()->get());
    }
    try {
      TrustedProxies check(c.trusted_proxies);
    } catch (const std::invalid_argument& e) {
      throw InputError(source, {}, "'server.trusted_proxies': " + std::string(e.what()));
    }
  }
  std::string base;
  r.text("base_path", base);
  const std::optional<std::string> normal = normal_base_path(base);
  if (!normal)
    throw InputError(source, {},
                     "'server.base_path' must be a path such as \"/salient\", got '" + base + "'");
  c.base_path = *normal;
}

void read_node_settings(TableReader& r, NodeConfig& node, const std::string& source) {
  r.text("id", node.id);
  if (node.id.size() > 64 ||
      node.id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.") !=
          std::string::npos)
    throw InputError(source, {},
                     "'node.id' must be at most 64 letters, digits, '-', '_' or '.', got '" + node.id + "'");
  if (const toml::array* roles = r.array("roles", "an array of roles (\"api\", \"slicer\", \"printers\")")) {
    node.roles = {false, false, false};
    for (const toml::node& n : *roles) {
      const InputLocation at = InputLocation::at_line(core::line_of(n));
      const std::optional<std::string> role = n.value<std::string>();
      if (role == "api")
        node.roles.api = true;
      else if (role == "slicer")
        node.roles.slicer = true;
      else if (role == "printers")
        node.roles.printers = true;
      else
        throw InputError(source, at, "'node.roles' entries are \"api\", \"slicer\" or \"printers\"");
    }
    if (!node.roles.api && !node.roles.slicer && !node.roles.printers)
      throw InputError(source, {}, "'node.roles' is empty: a node needs at least one role");
  }
  r.number("lease_seconds", node.lease_seconds, 1.0, 3600.0);
  r.integer("max_attempts", node.max_attempts, 1, 100);
}

}  // namespace

std::vector<std::string> role_names(const NodeRoles& roles) {
  std::vector<std::string> out;
  for (const auto& [on, name] :
       {std::pair{roles.api, "api"}, {roles.slicer, "slicer"}, {roles.printers, "printers"}})
    if (on) out.emplace_back(name);
  return out;
}

std::string role_list(const NodeRoles& roles) {
  std::string out;
  for (const std::string& name : role_names(roles)) out += (out.empty() ? "" : ",") + name;
  return out;
}

std::string default_node_id() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "local";
  std::string id(name);
  for (char& ch : id)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_' && ch != '.') ch = '_';
  return id.substr(0, 64);
}

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
    read_proxy_settings(r, c, source);
  });
  if (!(in_flight_mb >= upload_mb))
    throw InputError(source, {}, "'server.max_bodies_in_flight_mb' must be at least 'server.max_upload_mb'");
  c.max_bodies_in_flight_bytes = static_cast<std::size_t>(in_flight_mb * (1 << 20));
  c.max_upload_bytes = static_cast<std::size_t>(upload_mb * (1 << 20));
  c.max_json_bytes = static_cast<std::size_t>(json_kb * (1 << 10));
  core::read_section(top, "jobs", source, [&](TableReader& r) {
    r.integer("workers", c.workers, 1, 64);
    r.integer("queue_limit", c.queue_limit, 1, 100000);
    r.number("time_limit_minutes", c.job_time_limit_minutes, 0.01, 10080.0);
  });
  core::read_section(top, "store", source, [&](TableReader& r) {
    r.text("url", c.store_url);
    r.text("files", c.store_files);
  });
  if (!c.store_url.empty()) {
    try {
      DatabaseUrl::parse(c.store_url);
    } catch (const StoreError& e) {
      throw InputError(source, {}, std::string("'store.url': ") + e.what());
    }
  }
  core::read_section(top, "web", source, [&](TableReader& r) { r.text("vendor_dir", c.web_vendor_dir); });
  core::read_section(top, "zeroconf", source, [&](TableReader& r) {
    r.boolean("enabled", c.zeroconf);
    r.text("name", c.zeroconf_name);
  });
  core::read_section(top, "node", source, [&](TableReader& r) { read_node_settings(r, c.node, source); });
  // DNS-SD instance names are one label: at most 63 bytes, no control characters.
  if (c.zeroconf_name.size() > 63 || std::any_of(c.zeroconf_name.begin(), c.zeroconf_name.end(),
                                                 [](unsigned char ch) { return ch < 0x20 || ch == 0x7f; }))
    throw InputError(source, {}, "'zeroconf.name' must be at most 63 bytes without control characters");
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
      std::string kind(to_string(p.kind)), protocol;
      std::optional<unsigned> baud;
      std::optional<std::string> sim_args;
      r.text("kind", kind);
      r.text("port", p.port);
      if (r.has("baud")) r.integer("baud", baud.emplace(), 300, 4000000);
      r.text("protocol", protocol);
      r.text("profile", p.profile);
      if (r.has("sim_args")) r.text("sim_args", sim_args.emplace());
      r.text("machine", p.machine);
      r.boolean("autoconnect", p.autoconnect);
      r.boolean("auto_start", p.auto_start);
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
      if (protocol.empty())
        p.protocol = protocol_of_profile(p.profile);
      else if (const auto pr = printer_protocol_from(protocol))
        p.protocol = *pr;
      else
        throw InputError(source, at, "'printers.protocol' must be marlin or s3g, got '" + protocol + "'");
      if (p.protocol == PrinterProtocol::s3g && !protocol::s3g::find_machine(p.machine)) {
        std::string known;
        for (const std::string& id : protocol::s3g::machine_ids()) known += (known.empty() ? "" : ", ") + id;
        throw InputError(source, at,
                         "'printers.machine' must be one of " + known + ", got '" + p.machine + "'");
      }
      p.baud = baud.value_or(default_baud(p.protocol));
      p.sim_args = sim_args.value_or(default_sim_args(p.protocol));
      if (p.kind == PrinterKind::sim) {
        try {
          split_args(p.sim_args);  // checked now rather than at the first connect
        } catch (const std::invalid_argument& e) {
          throw InputError(source, at, "'printers.sim_args': " + std::string(e.what()));
        }
      }
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
