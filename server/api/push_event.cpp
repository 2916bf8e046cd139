#include "server/api/push_event.hpp"

#include <nlohmann/json.hpp>

#include "server/api/octoprint_json.hpp"
#include "server/common/json_text.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

// {name, path, display, origin, size, owner} of a print; `size` from whichever state still had it.
json print_payload(const PrintRecord& record, const PrinterStatus& before, const PrinterStatus& after) {
  json size = nullptr;
  for (const PrinterStatus* s : {&after, &before})
    if (s->print && s->print->record.id == record.id && s->print->file_bytes > 0) {
      size = s->print->file_bytes;
      break;
    }
  return {{"name", record.filename},
          {"path", record.filename},
          {"display", record.filename},
          {"origin", "local"},
          {"size", size},
          {"owner", nullptr},
          {"user", nullptr}};
}

// The print that just ended (the printer left a print for a state without one).
void ended(const PrinterStatus& before, const PrinterStatus& after, std::vector<PushEvent>& out) {
  if (!busy_printing(before.state) || busy_printing(after.state) || !after.last_print) return;
  const PrintRecord& r = *after.last_print;
  json payload = print_payload(r, before, after);
  payload["time"] = (r.finished_at ? *r.finished_at : r.started_at) - r.started_at;
  switch (r.state) {
    case PrintState::finished:
      out.push_back({"PrintDone", json_text(payload)});
      break;
    case PrintState::cancelled:
      out.push_back({"PrintCancelled", json_text(payload)});
      break;
    case PrintState::failed:
    case PrintState::interrupted:
      payload["reason"] = "error";
      out.push_back({"PrintFailed", json_text(payload)});
      break;
    case PrintState::printing:
    case PrintState::paused:
      break;
  }
}

}  // namespace

std::vector<PushEvent> push_events(const PrinterStatus& before, const PrinterStatus& after) {
  std::vector<PushEvent> out;
  if (before.state == after.state && before.error == after.error) return out;
  const PrinterState was = before.state, is = after.state;
  if (is == PrinterState::operational && !connected(was))
    out.push_back({"Connected", json_text(json{{"port", after.device}, {"baudrate", nullptr}})});
  if (after.print) {
    const json payload = print_payload(after.print->record, before, after);
    if (is == PrinterState::printing && was == PrinterState::paused)
      out.push_back({"PrintResumed", json_text(payload)});
    else if (is == PrinterState::printing && !busy_printing(was))
      out.push_back({"PrintStarted", json_text(payload)});
    else if (is == PrinterState::paused && was != PrinterState::paused)
      out.push_back({"PrintPaused", json_text(payload)});
  }
  ended(before, after, out);
  if (is == PrinterState::error)
    out.push_back({"Error", json_text(json{{"error", after.error}, {"reason", "connection"}})});
  if (connected(was) && !connected(is)) out.push_back({"Disconnected", "{}"});
  out.push_back({"PrinterStateChanged",
                 json_text(json{{"state_id", state_id(after)}, {"state_string", state_text(after)}})});
  return out;
}

}  // namespace salient::server
