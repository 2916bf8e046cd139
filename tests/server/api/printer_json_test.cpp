// The printer document of GET /api/v1/printers/{id} and "printer" events, made from a
// PrinterStatus: every field, progress and eta of a running print, and which prints can resume.
#include "server/api/printer_json.hpp"

#include <doctest/doctest.h>

using namespace salient::server;
using nlohmann::json;

namespace {

PrintRecord record(PrintState state, long long confirmed, long long total) {
  PrintRecord r;
  r.id = 3, r.printer_id = "sim", r.filename = "a.gcode", r.file_digest = "d";
  r.state = state, r.confirmed = confirmed, r.total = total, r.started_at = 100;
  return r;
}

}  // namespace

TEST_CASE("an idle printer: names for its kind, protocol and state, nulls for what it does not know") {
  PrinterStatus s;
  s.id = "bridge", s.kind = PrinterKind::tcp, s.profile = "ender3", s.state = PrinterState::error;
  s.error = "link lost";
  s.hotend.actual = 21.5;
  const json j = printer_status_json(s);
  CHECK(j["id"] == "bridge");
  CHECK(j["kind"] == "tcp");
  CHECK(j["protocol"] == "marlin");
  CHECK(j["state"] == "error");
  CHECK(j["error"] == "link lost");
  CHECK(j["firmware"].is_null());
  CHECK(j["device"].is_null());
  CHECK(j["temperatures"]["hotend"]["actual"] == 21.5);
  CHECK(j["temperatures"]["hotend"]["target"].is_null());
  CHECK(j["temperatures"]["bed"]["actual"].is_null());
  CHECK(j["print"].is_null());
  CHECK(j["last_print"].is_null());
  CHECK(j.size() == 11);
}

TEST_CASE("a running print: progress, elapsed and eta, and the last print says whether it can resume") {
  PrinterStatus s;
  s.id = "sim", s.state = PrinterState::paused;
  s.print = PrinterStatus::Running{record(PrintState::paused, 250, 1000), 30.0};
  s.last_print = record(PrintState::interrupted, 10, 1000);
  json j = printer_status_json(s);
  CHECK(j["state"] == "paused");
  CHECK(j["print"]["state"] == "paused");
  CHECK(j["print"]["progress"] == 0.25);
  CHECK(j["print"]["elapsed"] == 30.0);
  CHECK(j["print"]["eta"] == 90.0);
  CHECK(j["print"]["layer"].is_null());  // a file without layer marks
  s.print->layer = 3, s.print->layers = 40;
  CHECK(printer_status_json(s)["print"]["layer"] == 3);
  CHECK(printer_status_json(s)["print"]["layers"] == 40);
  CHECK(j["print"]["resumable"] == false);
  CHECK(j["print"]["job"].is_null());
  CHECK(j["last_print"]["state"] == "interrupted");
  CHECK(j["last_print"]["resumable"] == true);
  CHECK(j["last_print"].contains("eta") == false);

  s.print->record.confirmed = 5;  // under 1 %: the pace says too little for an eta
  CHECK(printer_status_json(s)["print"]["eta"].is_null());
  for (PrintState ended : {PrintState::finished, PrintState::cancelled})
    CHECK(print_record_json(record(ended, 10, 1000))["resumable"] == false);
  CHECK(print_record_json(record(PrintState::failed, 10, 1000))["resumable"] == true);
  CHECK(print_record_json(record(PrintState::failed, 0, 1000))["resumable"] == false);  // nothing done yet
}

TEST_CASE("every state has a name, and print states read back from their names") {
  for (PrinterState s :
       {PrinterState::disconnected, PrinterState::connecting, PrinterState::operational,
        PrinterState::printing, PrinterState::paused, PrinterState::cancelling, PrinterState::error})
    CHECK(!to_string(s).empty());
  CHECK(to_string(PrinterState::cancelling) == "cancelling");
  for (PrintState s : {PrintState::printing, PrintState::paused, PrintState::finished, PrintState::failed,
                       PrintState::cancelled, PrintState::interrupted})
    CHECK(print_state_from(to_string(s)) == s);
  CHECK(!print_state_from("done"));
  for (PrinterKind k : {PrinterKind::sim, PrinterKind::serial, PrinterKind::tcp})
    CHECK(printer_kind_from(to_string(k)) == k);
  CHECK(!printer_kind_from("usb"));
  for (PrinterProtocol p : {PrinterProtocol::marlin, PrinterProtocol::s3g})
    CHECK(printer_protocol_from(to_string(p)) == p);
  CHECK(to_string(PrinterProtocol::s3g) == "s3g");
  CHECK(!printer_protocol_from("x3g"));
}
