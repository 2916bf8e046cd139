// The push socket's events from changes of state (push_events) and the OctoPrint documents they
// share with the REST routes (octoprint_json): flags for finishing and cancelling, filepos in
// bytes, temperature samples.
#include "server/api/push_event.hpp"

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "server/api/octoprint_json.hpp"

using namespace salient::server;
using nlohmann::json;

namespace {

PrinterStatus at(PrinterState state, std::optional<PrintState> print = std::nullopt,
                 std::optional<PrintState> last = std::nullopt) {
  PrinterStatus s;
  s.id = "sim", s.state = state, s.device = "/dev/pts/3";
  PrintRecord r;
  r.id = 7, r.filename = "cube.gcode", r.started_at = 100, r.total = 1000;
  if (print) {
    s.print.emplace();
    s.print->record = r;
    s.print->record.state = *print;
    s.print->file_bytes = 20000, s.print->filepos = 5000, s.print->elapsed = 30;
    s.print->record.confirmed = 100;
  }
  if (last) {
    s.last_print = r;
    s.last_print->state = *last;
    s.last_print->finished_at = 160;
  }
  return s;
}

std::vector<std::string> types(const std::vector<PushEvent>& events) {
  std::vector<std::string> out;
  for (const auto& e : events) out.push_back(e.type);
  return out;
}

json payload(const std::vector<PushEvent>& events, const std::string& type) {
  for (const auto& e : events)
    if (e.type == type) return json::parse(e.payload);
  return nullptr;
}

}  // namespace

TEST_CASE("a print's life as OctoPrint's events") {
  using S = PrinterState;
  const auto start = push_events(at(S::operational), at(S::printing, PrintState::printing));
  CHECK(types(start) == std::vector<std::string>{"PrintStarted", "PrinterStateChanged"});
  CHECK(payload(start, "PrintStarted")["path"] == "cube.gcode");
  CHECK(payload(start, "PrintStarted")["size"] == 20000);
  CHECK(payload(start, "PrinterStateChanged") ==
        json{{"state_id", "PRINTING"}, {"state_string", "Printing"}});

  CHECK(types(push_events(at(S::printing, PrintState::printing), at(S::paused, PrintState::paused))) ==
        std::vector<std::string>{"PrintPaused", "PrinterStateChanged"});
  CHECK(types(push_events(at(S::paused, PrintState::paused), at(S::printing, PrintState::printing))) ==
        std::vector<std::string>{"PrintResumed", "PrinterStateChanged"});
  CHECK(types(push_events(at(S::printing, PrintState::printing), at(S::finishing, PrintState::printing))) ==
        std::vector<std::string>{"PrinterStateChanged"});

  const auto done =
      push_events(at(S::finishing, PrintState::printing), at(S::operational, {}, PrintState::finished));
  CHECK(types(done) == std::vector<std::string>{"PrintDone", "PrinterStateChanged"});
  CHECK(payload(done, "PrintDone")["time"] == 60.0);
  CHECK(payload(done, "PrintDone")["size"] == 20000);  // from the state before, which had the print

  const auto cancel =
      push_events(at(S::cancelling, PrintState::printing), at(S::operational, {}, PrintState::cancelled));
  CHECK(types(cancel) == std::vector<std::string>{"PrintCancelled", "PrinterStateChanged"});
  const auto lost =
      push_events(at(S::printing, PrintState::printing), at(S::error, {}, PrintState::interrupted));
  CHECK(types(lost) ==
        std::vector<std::string>{"PrintFailed", "Error", "Disconnected", "PrinterStateChanged"});
  CHECK(payload(lost, "PrintFailed")["reason"] == "error");

  CHECK(types(push_events(at(S::connecting), at(S::operational))) ==
        std::vector<std::string>{"Connected", "PrinterStateChanged"});
  CHECK(types(push_events(at(S::operational), at(S::disconnected))) ==
        std::vector<std::string>{"Disconnected", "PrinterStateChanged"});
  CHECK(push_events(at(S::operational), at(S::operational)).empty());
}

TEST_CASE("state flags: finishing and cancelling are their own flags, and printing stays on through them") {
  const auto flags = [](PrinterState s) { return state_json(at(s))["flags"]; };
  CHECK(flags(PrinterState::finishing)["finishing"] == true);
  CHECK(flags(PrinterState::finishing)["printing"] == true);
  CHECK(flags(PrinterState::finishing)["operational"] == true);
  CHECK(flags(PrinterState::finishing)["ready"] == false);
  CHECK(state_json(at(PrinterState::finishing))["text"] == "Finishing");
  CHECK(flags(PrinterState::cancelling)["cancelling"] == true);
  CHECK(flags(PrinterState::cancelling)["finishing"] == false);
  CHECK(flags(PrinterState::paused)["printing"] == false);
  CHECK(flags(PrinterState::printing)["finishing"] == false);
  CHECK(flags(PrinterState::operational)["ready"] == true);
  CHECK(flags(PrinterState::error)["closedOrError"] == true);
  PrinterStatus broken = at(PrinterState::error);
  broken.error = "link lost";
  CHECK(state_json(broken)["error"] == "link lost");
  CHECK(state_id(at(PrinterState::finishing)) == "FINISHING");
}

TEST_CASE("progress counts the file's bytes, job names the file, temperature samples in whole seconds") {
  const json p = progress_json(at(PrinterState::printing, PrintState::printing));
  CHECK(p["filepos"] == 5000);
  CHECK(p["completion"] == 25.0);
  CHECK(p["printTime"] == 30);
  CHECK(p["printTimeLeft"].is_number());
  CHECK(progress_json(at(PrinterState::operational))["completion"].is_null());

  const json analysis = {{"estimatedPrintTime", 90.5}, {"filament", {{"tool0", {{"length", 12}}}}}};
  const json j = print_job_json(at(PrinterState::printing, PrintState::printing), "", std::nullopt, analysis);
  CHECK(j["file"]["path"] == "cube.gcode");
  CHECK(j["file"]["size"] == 20000);
  CHECK(j["estimatedPrintTime"] == 90.5);
  CHECK(j["filament"]["tool0"]["length"] == 12);
  const json idle = print_job_json(at(PrinterState::operational), "", std::nullopt, nullptr);
  CHECK(idle["file"]["name"].is_null());

  TemperatureSample t;
  t.time = 1234.7, t.hotend.actual = 200.5, t.hotend.target = 210;
  const json s = temperature_sample_json(t);
  CHECK(s["time"] == 1234);
  CHECK(s["tool0"] == json{{"actual", 200.5}, {"target", 210.0}});
  CHECK(s["bed"]["actual"].is_null());
}
