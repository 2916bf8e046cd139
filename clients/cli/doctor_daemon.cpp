// The daemon's side of `salient doctor`: reachable, the key accepted, its printers, its clock.
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>

#include "clients/cli/daemon_client.hpp"
#include "clients/cli/doctor.hpp"

namespace salient::cli::doctor {
namespace {

using nlohmann::json;

// "Thu, 03 Dec 2026 14:05:00 GMT" (RFC 9110's IMF-fixdate) as seconds since the epoch.
std::optional<std::time_t> parse_http_date(const std::string& text) {
  std::tm tm{};
  const char* end = ::strptime(text.c_str(), "%a, %d %b %Y %H:%M:%S GMT", &tm);
  if (!end || *end != '\0') return std::nullopt;
  return ::timegm(&tm);
}

Check clock_check(const std::string& date) {
  const std::optional<std::time_t> server = parse_http_date(date);
  if (!server)
    return {Verdict::warn, "clock", "salientd sent no Date header to compare with (an older salientd?)", ""};
  const long skew = static_cast<long>(std::time(nullptr) - *server);
  const std::string found = "this machine's clock is " + std::to_string(std::labs(skew)) + " s " +
                            (skew >= 0 ? "ahead of" : "behind") + " salientd's";
  // The Date header has whole seconds and the request takes some: a few seconds is no skew.
  if (std::labs(skew) <= 5) return {Verdict::ok, "clock", found, ""};
  return {std::labs(skew) > 300 ? Verdict::fail : Verdict::warn, "clock", found,
          "turn on time synchronisation on both machines: sudo timedatectl set-ntp true (certificates, "
          "sessions and print times depend on it)"};
}

// What /healthz says of salientd's database: its kind, schema and round trip; 503 when it does not
// answer (the farm's PostgreSQL down, or a wrong [store] url).
Check database_check(const std::string& body) {
  const json h = json::parse(body, nullptr, false);
  if (!h.is_object() || !h.contains("database") || !h["database"].is_object())
    return {Verdict::warn, "database", "salientd does not report its database (an older salientd?)", ""};
  const json& d = h["database"];
  if (h.value("status", "") != "ok" || !d.contains("kind"))
    return {
        Verdict::fail, "database", "salientd cannot reach its database",
        "check [store] url in /etc/salient/salientd.toml and that the database runs (a farm's PostgreSQL: "
        "systemctl status postgresql, pg_isready -h HOST); salientd's log has the error "
        "(journalctl -u salientd)"};
  const std::string node = h.value("node", "");
  std::string found = d.value("kind", "") + " answers in " + std::to_string(d.value("ms", 0.0)).substr(0, 5) +
                      " ms, schema " + std::to_string(d.value("schema", 0)) +
                      (node.empty() ? "" : " (node " + node + ")");
  if (d.value("schema", 0) != d.value("latest_schema", 0))
    return {Verdict::warn, "database",
            found + ", but this salientd expects schema " + std::to_string(d.value("latest_schema", 0)),
            "upgrade every node of the farm to the same salient version"};
  return {Verdict::ok, "database", found, ""};
}

Check printer_check(const json& p) {
  const std::string id = p.value("id", "?"), state = p.value("state", "?");
  const std::string error =
      p.contains("error") && p["error"].is_string() ? p["error"].get<std::string>() : "";
  const std::string device =
      p.contains("device") && p["device"].is_string() ? " on " + p["device"].get<std::string>() : "";
  const std::string name = "printer " + id;
  if (state == "error") {
    std::string fix =
        "salient printers shows it; connect again with POST /api/v1/printers/" + id + "/connect";
    if (error.find("ermission denied") != std::string::npos)
      fix =
          "salientd's user may not open the device: add it to the device's group (dialout), restart salientd";
    else if (error.find("No such file") != std::string::npos || error.find("is gone") != std::string::npos)
      fix = "the device is not there: plug the printer in and power it (salientd reconnects by itself)";
    else if (error.find("disconnected") != std::string::npos || error.find("link lost") != std::string::npos)
      fix =
          "the link was lost (cable, power, a board reset): check them; a serial printer is connected "
          "again by itself when its device is back";
    else if (error.find("busy") != std::string::npos)
      fix = "another program holds the port (see 'in use' above): stop it";
    return {Verdict::fail, name, state + ": " + error, fix};
  }
  if (state == "disconnected")
    return {Verdict::warn, name, "disconnected", "connect it: POST /api/v1/printers/" + id + "/connect"};
  return {Verdict::ok, name, state + device, ""};
}

// The key when none is given: the data directory's api-key file, which salientd writes at its first
// start (/var/lib/salient/api-key once installed, readable by root and salient). `unreadable`: the
// file is there but this user may not read it.
std::string key_from_data_dir(const Options& o, std::string& unreadable) {
  if (const char* env = std::getenv("SALIENT_API_KEY"); !o.key.empty() || (env && *env)) return o.key;
  const std::string dir = find_data_dir(o.data_dir);
  if (dir.empty()) return {};
  const std::string path = dir + "/api-key";
  std::ifstream f(path);
  std::string key;
  if (f)
    std::getline(f, key);
  else if (::access(path.c_str(), F_OK) == 0 || errno == EACCES)  // there, or its directory closed
    unreadable = path;
  return key;
}

}  // namespace

std::vector<Check> daemon_checks(const Options& o) {
  std::vector<Check> out;
  DaemonAddress address;
  std::string unreadable;
  try {
    address = resolve_daemon(o.server, key_from_data_dir(o, unreadable));
  } catch (const DaemonError& e) {
    return {{Verdict::fail, "daemon", e.what(), "--server http://HOST:PORT (or $SALIENT_SERVER)"}};
  }
  const std::string where = address.host + ":" + address.port;
  DaemonClient client(address);
  DaemonReply health;
  try {
    health = client.request("GET", "/healthz");
  } catch (const DaemonError& e) {
    if (e.status() == 503) {  // salientd runs; its database does not answer
      out.push_back({Verdict::ok, "daemon", "salientd answers at " + where, ""});
      out.push_back(database_check(R"({"status": "unavailable", "database": {}})"));
      return out;
    }
    out.push_back({Verdict::fail, "daemon", e.what(),
                   "start salientd (sudo systemctl start salientd, or make run in a checkout); if it runs "
                   "elsewhere: --server http://HOST:PORT or $SALIENT_SERVER"});
    return out;
  }
  out.push_back({Verdict::ok, "daemon", "salientd answers at " + where, ""});
  out.push_back(clock_check(health.date));
  out.push_back(database_check(health.body));
  if (address.key.empty() && !unreadable.empty()) {
    out.push_back({Verdict::fail, "key", "no API key given, and this user may not read " + unreadable,
                   "run it as root (sudo salient doctor), or give the key: --key KEY or $SALIENT_API_KEY"});
    return out;
  }
  if (address.key.empty()) {
    out.push_back({Verdict::fail, "key", "no API key given",
                   "--key KEY or $SALIENT_API_KEY; the first key is in the data directory's api-key file "
                   "(sudo cat /var/lib/salient/api-key)"});
    return out;
  }
  DaemonReply printers;
  try {
    printers = client.request("GET", "/api/v1/printers");
  } catch (const DaemonError& e) {
    if (e.status() == 401)
      out.push_back({Verdict::fail, "key", "salientd refused the key (HTTP 401): it is wrong or was revoked",
                     "use a valid key: --key KEY or $SALIENT_API_KEY (the first one is in DATA/api-key; an "
                     "admin makes more with `salient keys create`)"});
    else
      out.push_back({Verdict::fail, "key", e.what(), "see salientd's log (journalctl -u salientd)"});
    return out;
  }
  out.push_back({Verdict::ok, "key", "accepted by salientd", ""});
  const json list = json::parse(printers.body, nullptr, false);
  if (!list.is_object() || !list.contains("printers") || !list["printers"].is_array())
    return out.push_back({Verdict::warn, "printers", "salientd's printer list is not as expected", ""}), out;
  if (list["printers"].empty())
    out.push_back({Verdict::warn, "printers", "salientd has no printer configured",
                   "add one under [[printers]] in /etc/salient/salientd.toml and restart salientd"});
  for (const json& p : list["printers"]) out.push_back(printer_check(p));
  return out;
}

}  // namespace salient::cli::doctor
