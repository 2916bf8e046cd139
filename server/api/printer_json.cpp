#include "server/api/printer_json.hpp"

#include <algorithm>

namespace salient::server {
namespace {

using nlohmann::json;

json optional_number(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

json optional_text(const std::string& s) {
  return s.empty() ? json(nullptr) : json(s);
}

json temperature_json(const Temperature& t) {
  return {{"actual", optional_number(t.actual)}, {"target", optional_number(t.target)}};
}

}  // namespace

json print_record_json(const PrintRecord& p) {
  return {
      {"id", p.id},
      {"job", p.job_id ? json(*p.job_id) : json(nullptr)},
      {"file", p.filename},
      {"state", to_string(p.state)},
      {"confirmed", p.confirmed},
      {"total", p.total},
      {"progress", p.total > 0 ? double(p.confirmed) / double(p.total) : 0.0},
      {"reason", p.reason ? json(*p.reason) : json(nullptr)},
      {"started_at", p.started_at},
      {"finished_at", p.finished_at ? json(*p.finished_at) : json(nullptr)},
      {"filament_mm", p.filament_mm},
      {"paused_seconds", p.paused_seconds},
      // From start to end, and of that the time printing (Moonraker's total and print duration).
      {"duration", p.finished_at ? json(std::max(0.0, *p.finished_at - p.started_at)) : json(nullptr)},
      {"print_duration",
       p.finished_at ? json(std::max(0.0, *p.finished_at - p.started_at - p.paused_seconds)) : json(nullptr)},
      // What a restart or a pulled cable leaves: where `POST …/print {"resume": id}` goes on from.
      {"resumable", (p.state == PrintState::failed || p.state == PrintState::interrupted) &&
                        p.confirmed > 0 && p.confirmed < p.total}};
}

json printer_status_json(const PrinterStatus& s) {
  json print = nullptr;
  if (s.print) {
    print = print_record_json(s.print->record);
    print["elapsed"] = s.print->elapsed;
    print["eta"] = optional_number(s.print->eta());
    print["layer"] = s.print->layers ? json(s.print->layer) : json(nullptr);
    print["layers"] = s.print->layers ? json(s.print->layers) : json(nullptr);
  }
  return {{"id", s.id},
          {"kind", to_string(s.kind)},
          {"protocol", to_string(s.protocol)},
          {"profile", s.profile},
          {"state", to_string(s.state)},
          {"error", optional_text(s.error)},
          {"firmware", optional_text(s.firmware)},
          {"device", optional_text(s.device)},
          {"temperatures", {{"hotend", temperature_json(s.hotend)}, {"bed", temperature_json(s.bed)}}},
          {"print", print},
          {"last_print", s.last_print ? print_record_json(*s.last_print) : json(nullptr)}};
}

nlohmann::json print_totals_json(const PrintTotals& t) {
  return {{"prints", t.prints},
          {"finished", t.finished},
          {"cancelled", t.cancelled},
          {"failed", t.failed},
          {"interrupted", t.interrupted},
          {"total_seconds", t.total_seconds},
          {"print_seconds", t.print_seconds},
          {"filament_mm", t.filament_mm},
          {"longest_seconds", t.longest_seconds},
          {"longest_print_seconds", t.longest_print_seconds}};
}

nlohmann::json print_queue_json(const std::string& key, const std::vector<QueueEntry>& entries) {
  nlohmann::json list = nlohmann::json::array();
  for (const QueueEntry& e : entries)
    list.push_back({{"entry", e.id},
                    {"position", e.position},
                    {"state", e.slicing ? "slicing" : "queued"},
                    {e.kind, e.ref},
                    {"queued_at", e.created_at}});
  if (key.rfind("profile/", 0) == 0) return {{"profile", key.substr(8)}, {"entries", list}};
  return {{"printer", key}, {"entries", list}};
}

nlohmann::json farm_printer_json(const FarmPrinter& p, bool live) {
  nlohmann::json out = nlohmann::json::parse(p.status, nullptr, false);  // the node wrote it; a bad one is {}
  if (!out.is_object()) out = nlohmann::json::object();
  out["id"] = p.id;
  out["profile"] = p.profile;
  out["node"] = p.node;
  if (!live) out["state"] = "offline";
  return out;
}

}  // namespace salient::server
