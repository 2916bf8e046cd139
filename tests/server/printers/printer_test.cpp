// A Printer against the real simulator on a pseudo-terminal (salient-sim, started by the Printer
// as the daemon does): connect, print exactly, pause and resume, cancel, the 409s, emergency
// stop, and a stop in the middle of a print that leaves it resumable — and the resume finishes
// exactly the rest of the file.
#include "server/printers/printer.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "protocol/gcode/command_code.hpp"
#include "protocol/gcode/program.hpp"
#include "protocol/marlin/line_codec.hpp"
#include "server/api/printer_json.hpp"
#include "server/common/domain_error.hpp"
#include "server/printers/sim_process.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// A G-code file of n moves (with comments and blank lines, as slicers write them).
std::string make_gcode(int n) {
  std::string g = "; test print\nM104 S200\nM140 S60\nG28\nG90\nM82\nG92 E0\n\n";
  for (int i = 0; i < n; ++i) {
    g += "G1 X" + std::to_string(10 + i % 100) + " Y" + std::to_string(10 + (i / 100) % 100) + " E" +
         std::to_string(i * 0.01).substr(0, 6) + " F3000 ; move " + std::to_string(i) + "\n";
    if (i % 500 == 0) g += ";LAYER_CHANGE\n";
  }
  return g + "M104 S0\nM140 S0\nM84\n";
}

std::vector<std::string> commands_of(const std::string& gcode) {
  std::vector<std::string> out;
  std::istringstream in(gcode);
  for (std::string line; std::getline(in, line);)
    if (auto c = salient::protocol::marlin::strip_comment(line); !c.empty()) out.push_back(c);
  return out;
}

// The simulator's log without what the host adds (M110, M115, M155, M105).
std::vector<std::string> executed(const std::filesystem::path& log) {
  std::vector<std::string> out;
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    const std::string word = line.substr(0, line.find(' '));
    if (!line.empty() && word != "M110" && word != "M115" && word != "M155" && word != "M105")
      out.push_back(line);
  }
  return out;
}

json status(const Printer& p) {
  return printer_status_json(p.status());
}

template <typename F>
bool eventually(F&& ok, std::chrono::milliseconds limit = 20s) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until) {
    if (ok()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return ok();
}

struct Fixture {
  salient::test::ScratchDir dir;
  Store store;
  std::atomic<int> state_events{0}, progress_events{0};
  explicit Fixture(const std::string& name) : dir(name), store(dir.path / "data") {
    ::setenv("SALIENT_SIM", SALIENT_SIM_PROGRAM, 1);
  }
  PrinterConfig sim(const std::string& args) {
    PrinterConfig c;
    c.id = "sim";
    c.sim_args = args + " --log " + (dir.path / "sim.log").string();
    return c;
  }
  Printer::Hooks hooks() {
    Printer::Hooks h;
    h.changed = [this](const Printer&, bool progress) { ++(progress ? progress_events : state_events); };
    return h;
  }
  PrintRequest file(const std::string& gcode) {
    return {std::nullopt, store.files().put(gcode), "test.gcode", 0};
  }
};

}  // namespace

TEST_CASE("connect, print exactly, refuse what the state does not allow, and tell about it") {
  Fixture f("printer-print");
  Printer p(f.sim("--advanced-ok --time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  CHECK(status(p)["firmware"].get<std::string>().find("Marlin") != std::string::npos);
  CHECK_THROWS_AS(p.connect(), Conflict);  // already connected
  CHECK_THROWS_AS(p.pause(), Conflict);    // nothing to pause

  const std::string gcode = make_gcode(20000);
  const long long id = p.print(f.file(gcode));
  CHECK(p.state() == PrinterState::printing);
  try {
    p.print(f.file(gcode));
    FAIL("a second print was accepted");
  } catch (const DomainError& e) {
    CHECK(e.kind() == ErrorKind::conflict);
  }
  p.command({"M220 S100 ; a console line during the print"});  // goes into the stream
  CHECK_THROWS_AS(p.disconnect(), Conflict);
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }, 60s));
  const json s = status(p);
  CHECK(s["last_print"]["id"] == id);
  CHECK(s["last_print"]["state"] == "finished");
  CHECK(s["last_print"]["confirmed"] == s["last_print"]["total"]);
  CHECK(s["last_print"]["total"] == commands_of(gcode).size());
  CHECK(f.state_events >= 3);  // connecting, operational, printing, …
  CHECK(f.progress_events >= 1);
  CHECK(p.counters().prints_finished == 1);
  p.stop();  // the simulator flushes its log as it exits
  std::vector<std::string> log = executed(f.dir.path / "sim.log");
  CHECK(std::count(log.begin(), log.end(), "M220 S100") == 1);
  log.erase(std::remove(log.begin(), log.end(), "M220 S100"), log.end());
  CHECK(log == commands_of(gcode));  // and nothing of the file lost or repeated around it
  // The database has it too, for the next start.
  const auto stored = PrintStore(f.store.db()).get(id);
  REQUIRE(stored);
  CHECK(stored->state == PrintState::finished);
}

TEST_CASE("pause holds the stream, resume goes on, cancel stops and cools down") {
  Fixture f("printer-pause");
  Printer p(f.sim("--advanced-ok --time-scale 0.05 --heat-time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  const std::string gcode = make_gcode(5000);
  p.print(f.file(gcode));
  REQUIRE(eventually([&] { return status(p)["print"].is_object() && status(p)["print"]["confirmed"] > 50; }));
  p.pause();
  CHECK(p.state() == PrinterState::paused);
  // The store says so at once, not with the next confirmed line (a pause may confirm none): other
  // nodes and a restart read it there.
  const long long print_id = status(p)["print"]["id"];
  CHECK(PrintStore(f.store.db()).get(print_id)->state == PrintState::paused);
  std::this_thread::sleep_for(500ms);  // what was in flight settles
  const long long held = status(p)["print"]["confirmed"];
  p.command({"M106 S255"});  // paused, a console line still goes (a fan, a temperature)
  std::this_thread::sleep_for(500ms);
  CHECK(status(p)["print"]["confirmed"] == held);
  // The layer under way is the one of the next command to confirm, as the file's marks count it.
  const auto program = salient::protocol::Program::parse(gcode);
  CHECK(status(p)["print"]["layers"] == program.layers());
  CHECK(status(p)["print"]["layer"] == program[static_cast<std::size_t>(held)].layer + 1);
  p.resume();
  CHECK(PrintStore(f.store.db()).get(print_id)->state == PrintState::printing);
  REQUIRE(eventually([&] { return status(p)["print"]["confirmed"] > held; }));
  p.command({"M117 asked before the cancel"});  // answered 204: it goes, ahead of the cleanup
  p.cancel();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  CHECK(status(p)["last_print"]["state"] == "cancelled");
  p.stop();
  const auto log = executed(f.dir.path / "sim.log");
  REQUIRE(log.size() > 3);
  const auto heaters_off = std::find(log.rbegin(), log.rend(), "M104 S0");
  CHECK(heaters_off - log.rbegin() < 8);  // heaters off after the cancel
  CHECK(std::count(log.begin(), log.end(), "M117 asked before the cancel") == 1);
  CHECK(std::find(log.rbegin(), log.rend(), "M117 asked before the cancel") > heaters_off);
  // The fan line went while paused: right after the commands confirmed before the pause.
  const auto fan = std::find(log.begin(), log.end(), "M106 S255");
  REQUIRE(fan != log.end());
  CHECK(fan - log.begin() >= held);
}

// Issue 32: the printer's thread wrote the progress itself, so a database that held writes (a
// PostgreSQL frozen for 21 s) stopped the print as long. Another connection holding SQLite's
// write lock is such a database: the print must go on meanwhile, and its row catch up after.
TEST_CASE("a database that holds every write does not hold up the print") {
  Fixture f("printer-db-held");
  Printer p(f.sim("--advanced-ok --time-scale 0.05 --heat-time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.print(f.file(make_gcode(20000)));
  REQUIRE(eventually([&] { return status(p)["print"].is_object() && status(p)["print"]["confirmed"] > 50; }));
  const long long print_id = status(p)["print"]["id"];
  const long long before = status(p)["print"]["confirmed"];
  long long during = 0;
  {
    Database locker(f.dir.path / "data" / "salient.db");
    locker.exec("BEGIN EXCLUSIVE");  // every write waits (and gives up after SQLite's busy timeout)
    std::this_thread::sleep_for(2s);
    during = status(p)["print"]["confirmed"];
    locker.exec("COMMIT");
  }
  CHECK(p.state() == PrinterState::printing);
  INFO("confirmed " << before << " before, " << during << " after 2 s");
  CHECK(during - before > 50);  // lines kept being confirmed (477 in Release; 1 when the thread wrote)
  REQUIRE(eventually([&] { return PrintStore(f.store.db()).get(print_id)->confirmed >= during; }, 10s));
  p.cancel();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.stop();
}

std::vector<PrinterState> states_of(const std::vector<PrinterStatus>& changes) {
  std::vector<PrinterState> out;
  for (const PrinterStatus& s : changes) out.push_back(s.state);
  return out;
}

TEST_CASE("every change of state is kept in order, with the status then: printing, finishing, operational") {
  Fixture f("printer-changes");
  Printer p(f.sim("--advanced-ok --time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  std::uint64_t seen = 0;
  CHECK(states_of(p.state_changes_since(seen)) ==
        std::vector<PrinterState>{PrinterState::connecting, PrinterState::operational});
  CHECK(p.state_changes_since(seen).empty());  // read up to here
  const std::string gcode = make_gcode(3000);
  p.print(f.file(gcode));
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }, 60s));
  const std::vector<PrinterStatus> changes = p.state_changes_since(seen);
  // However short the finishing phase, a watcher that reads only now still sees it, in order.
  CHECK(states_of(changes) == std::vector<PrinterState>{PrinterState::printing, PrinterState::finishing,
                                                        PrinterState::operational});
  REQUIRE(changes.size() == 3);
  REQUIRE(changes[1].print);  // finishing: the print is still under way, every byte of it done
  CHECK(changes[1].print->file_bytes == gcode.size());
  CHECK(changes[1].print->filepos == gcode.size());
  CHECK(changes[1].print->record.confirmed == changes[1].print->record.total);
  CHECK(!changes[2].print);
  REQUIRE(changes[2].last_print);
  CHECK(changes[2].last_print->state == PrintState::finished);
  CHECK(busy_printing(PrinterState::finishing));
  p.stop();
}

TEST_CASE("a cancel is kept as cancelling then operational, and progress counts the file's bytes") {
  Fixture f("printer-cancel-changes");
  Printer p(f.sim("--advanced-ok --time-scale 0.05 --heat-time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  std::uint64_t seen = 0;
  p.state_changes_since(seen);
  const std::string gcode = make_gcode(5000);
  p.print(f.file(gcode));
  REQUIRE(eventually([&] { return p.status().print && p.status().print->record.confirmed > 50; }));
  const PrinterStatus mid = p.status();
  const auto program = salient::protocol::Program::parse(gcode);
  const auto next = static_cast<std::size_t>(mid.print->record.confirmed);
  CHECK(mid.print->filepos == program[next].offset);  // bytes of the file, not commands or lines
  CHECK(mid.print->filepos > next);
  CHECK(gcode[mid.print->filepos - 1] == '\n');
  p.cancel();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  const std::vector<PrinterStatus> changes = p.state_changes_since(seen);
  CHECK(states_of(changes) == std::vector<PrinterState>{PrinterState::printing, PrinterState::cancelling,
                                                        PrinterState::operational});
  REQUIRE(changes.size() == 3);
  REQUIRE(changes[2].last_print);
  CHECK(changes[2].last_print->state == PrintState::cancelled);
  p.stop();
}

TEST_CASE("a print waiting behind console commands is cancelled or paused as itself, never the commands") {
  Fixture f("printer-cancel-waiting");
  Printer p(f.sim("--advanced-ok --time-scale 0.05 --heat-time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  const std::string gcode = make_gcode(300);
  // A dwell of 1.5 s (30 s at time scale 0.05) asked for before the print: it goes first, and the
  // print waits behind it, "printing" already.
  p.command({"G4 S30"});
  std::this_thread::sleep_for(300ms);  // the dwell is under way when the print comes
  std::uint64_t seen = 0;
  p.state_changes_since(seen);
  const long long cancelled = p.print(f.file(gcode));
  p.cancel();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  CHECK(states_of(p.state_changes_since(seen)) == std::vector<PrinterState>{PrinterState::printing,
                                                                            PrinterState::cancelling,
                                                                            PrinterState::operational});
  const auto record = PrintStore(f.store.db()).get(cancelled);
  REQUIRE(record);
  CHECK(record->state == PrintState::cancelled);
  CHECK(record->confirmed == 0);
  REQUIRE(status(p)["last_print"]["id"] == cancelled);

  // Paused while it waits: it begins paused, and a resume prints it exactly.
  p.command({"G4 S30"});
  const long long paused = p.print(f.file(gcode));
  p.pause();
  std::this_thread::sleep_for(2500ms);  // the dwell is over: the print has been taken, and holds
  CHECK(p.state() == PrinterState::paused);
  CHECK(p.status().print->record.confirmed == 0);
  p.resume();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }, 60s));
  CHECK(status(p)["last_print"]["id"] == paused);
  CHECK(status(p)["last_print"]["state"] == "finished");
  p.stop();
  std::vector<std::string> want{"G4 S30", "G4 S30"};
  for (const std::string& c : commands_of(gcode)) want.push_back(c);
  CHECK(executed(f.dir.path / "sim.log") == want);  // the cancelled print sent nothing
}

TEST_CASE("a stop mid-print leaves it interrupted and resumable, and the resume prints exactly the rest") {
  Fixture f("printer-resume");
  const std::string gcode = make_gcode(8000);
  long long id = 0, confirmed = 0;
  {
    Printer p(f.sim("--advanced-ok --time-scale 0.05 --heat-time-scale 0"), f.store, f.hooks());
    p.start();
    REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
    id = p.print(f.file(gcode));
    REQUIRE(
        eventually([&] { return status(p)["print"].is_object() && status(p)["print"]["confirmed"] > 200; }));
    p.stop();
    const auto r = PrintStore(f.store.db()).get(id);
    REQUIRE(r);
    CHECK(r->state == PrintState::interrupted);
    confirmed = r->confirmed;
    CHECK(confirmed > 200);
    CHECK(confirmed < r->total);
  }
  std::filesystem::rename(f.dir.path / "sim.log", f.dir.path / "first.log");
  Printer p(f.sim("--advanced-ok --time-scale 0"), f.store, f.hooks());
  CHECK(status(p)["last_print"]["resumable"] == true);
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  const auto record = PrintStore(f.store.db()).get(id);
  p.print(
      {record->job_id, record->file_digest, record->filename, static_cast<std::size_t>(record->confirmed)});
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }, 60s));
  CHECK(status(p)["last_print"]["state"] == "finished");
  p.stop();
  const auto all = commands_of(gcode);
  const std::vector<std::string> rest(all.begin() + confirmed, all.end());
  const auto log = executed(f.dir.path / "sim.log");
  REQUIRE(log.size() >= rest.size());
  // The prelude (heat, modes, position) first, then exactly the commands not yet acknowledged.
  CHECK(std::vector<std::string>(log.end() - static_cast<std::ptrdiff_t>(rest.size()), log.end()) == rest);
}

TEST_CASE("emergency stop halts the firmware, and the printer reports an error until connected again") {
  Fixture f("printer-estop");
  Printer p(f.sim("--advanced-ok --emergency-parser --time-scale 0.05 --heat-time-scale 0"), f.store,
            f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.print(f.file(make_gcode(5000)));
  REQUIRE(eventually([&] { return status(p)["print"].is_object() && status(p)["print"]["confirmed"] > 10; }));
  p.emergency_stop();
  REQUIRE(eventually([&] { return p.state() == PrinterState::error; }));
  CHECK(status(p)["last_print"]["state"] == "failed");
  CHECK(status(p)["error"].get<std::string>().find("emergency stop") != std::string::npos);
  CHECK_THROWS_AS(p.command({"G28"}), Conflict);
  p.connect();  // a fresh simulator, as a reset board
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.command({"M106 S255", "M107"});
  p.stop();
}

TEST_CASE("a file holding M110 or a numbered line is refused before anything goes, naming the line") {
  // M110 N0 in a file made the firmware ask for line 1 again, and the host replayed the file
  // from there forever, stuck in finishing.
  Fixture f("printer-m110");
  Printer p(f.sim("--advanced-ok --time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  for (const std::string bad : {"M110 N0", "N7 G1 X5"}) {
    INFO(bad);
    const std::string gcode = "G28\n; a comment\nG1 X10 F3000\n" + bad + " ; the host's business\nG1 X20\n";
    try {
      p.print(f.file(gcode));
      FAIL("the file was accepted");
    } catch (const DomainError& e) {
      CHECK(e.kind() == ErrorKind::unprocessable);
      CHECK(std::string(e.what()).find("line 4") != std::string::npos);
      CHECK(std::string(e.what()).find(bad.substr(0, 2)) != std::string::npos);
    }
    CHECK(p.state() == PrinterState::operational);
  }
  p.stop();
  CHECK(executed(f.dir.path / "sim.log").empty());  // nothing of either file went
}

TEST_CASE("moves and homing wait for the print: refused while it prints unless forced, sent paused or idle") {
  Fixture f("printer-motion-guard");
  Printer p(f.sim("--advanced-ok --time-scale 0.05 --heat-time-scale 0"), f.store, f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.command({"G28 X"});  // idle: it goes
  p.print(f.file(make_gcode(5000)));
  REQUIRE(eventually([&] { return status(p)["print"].is_object() && status(p)["print"]["confirmed"] > 10; }));
  for (const std::string move : {"G28", "G1 X5 Y5", "g0 z5", "G92 E0", "M84", "G29"}) {
    INFO(move);
    try {
      p.command({"M117 refused with the move", move});
      FAIL("a move was sent into the print");
    } catch (const Conflict& e) {
      const std::string what = e.what();
      CHECK(what.find("is printing") != std::string::npos);
      CHECK(what.find(salient::protocol::command_code(move)->text) != std::string::npos);
      CHECK(what.find("force") != std::string::npos);
    }
  }
  p.command({"M220 S90"});        // not a move: into the stream
  p.command({"G1 X7 Y7"}, true);  // forced: the owner's call
  p.pause();
  p.command({"G1 Z10"});  // paused: moving the head away is what a pause is for
  p.cancel();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.stop();
  const auto log = executed(f.dir.path / "sim.log");
  CHECK(std::count(log.begin(), log.end(), "G28 X") == 1);
  CHECK(std::count(log.begin(), log.end(), "M117 refused with the move") == 0);
  CHECK(std::count(log.begin(), log.end(), "G92 E0") == 1);  // the file's own
  CHECK(std::count(log.begin(), log.end(), "M220 S90") == 1);
  CHECK(std::count(log.begin(), log.end(), "G1 X7 Y7") == 1);
  CHECK(std::count(log.begin(), log.end(), "G1 Z10") == 1);
}

TEST_CASE("a print held in finishing by a console line (a heating wait) can still be cancelled") {
  Fixture f("printer-cancel-finishing");
  // Heating 5 times slower than real: M109 S250 would hold the link for minutes.
  Printer p(f.sim("--advanced-ok --emergency-parser --time-scale 0.05 --heat-time-scale 5"), f.store,
            f.hooks());
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }));
  p.print(f.file("G1 X10 F3000\nG4 S20 ; a second\n"));
  REQUIRE(eventually([&] { return status(p)["print"].is_object() && status(p)["print"]["confirmed"] >= 1; }));
  p.command({"M109 S250"});  // behind the file's last line: the file is done before it is
  REQUIRE(eventually([&] { return p.state() == PrinterState::finishing; }));
  std::this_thread::sleep_for(300ms);
  REQUIRE(p.state() == PrinterState::finishing);  // held by the heating wait
  p.cancel();
  REQUIRE(eventually([&] { return p.state() == PrinterState::operational; }, 10s));
  CHECK(status(p)["last_print"]["state"] == "cancelled");
  p.stop();
}

TEST_CASE("a simulator that cannot start is an error naming it, not a hang") {
  Fixture f("printer-bad-sim");
  Printer p(f.sim("--bufsize 7"), f.store, f.hooks());  // salient-sim refuses it
  p.start();
  REQUIRE(eventually([&] { return p.state() == PrinterState::error; }));
  CHECK(status(p)["error"].get<std::string>().find("cannot connect") != std::string::npos);
}

TEST_CASE("sim_args split like a shell would") {
  CHECK(split_args("--a 1  --b 'x y' \"z\"") == std::vector<std::string>{"--a", "1", "--b", "x y", "z"});
  CHECK(split_args("").empty());
  CHECK_THROWS_AS(split_args("--log 'open"), std::invalid_argument);
}
