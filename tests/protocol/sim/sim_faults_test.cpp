// The faults at a known moment (silent-after, rerequest, busy-for, malformed-ok, reset-on-open),
// on SimFirmware driven directly: exactly what the host would see, and when.
#include "protocol/sim/sim_faults.hpp"

#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/marlin/marlin_reply.hpp"
#include "protocol/sim/sim_firmware.hpp"

using namespace salient::protocol::sim;
using salient::protocol::marlin::frame;
using std::chrono::seconds;

namespace {

std::string line(long long n, const std::string& command) {
  return frame(static_cast<std::uint64_t>(n), command) + "\n";
}

std::string talk(SimFirmware& fw, const std::string& bytes, Micros t) {
  fw.receive(bytes, t);
  fw.advance(t);
  return fw.take_output(t);
}

SimFirmware with_faults(const std::string& spec) {
  SimConfig c;
  c.faults = parse_faults(spec);
  return SimFirmware(c);
}

struct Said {
  Micros at;
  std::string text;
};

// Runs the firmware by its own wake-ups until `end`: what it said, and when.
std::vector<Said> run_until(SimFirmware& fw, Micros end) {
  std::vector<Said> out;
  for (Micros t = fw.next_wakeup(); t <= end; t = fw.next_wakeup()) {
    fw.advance(t);
    if (std::string s = fw.take_output(t); !s.empty()) out.push_back({t, s});
  }
  return out;
}

const std::string kBanner =
    "start\necho:Marlin 2.1.2 (salient-sim)\necho: Last Updated: 2026-11-22 | Author: (salient-sim)\n";

}  // namespace

TEST_CASE("silent-after: after command N's ok the board says nothing and loses what it is sent") {
  SimFirmware fw = with_faults("silent-after=3");
  CHECK(talk(fw, "G1 X1\nG1 X2\nG1 X3\nG1 X4\n", Micros{0}) == "ok\nok\nok\n");
  CHECK(fw.state() == SimFirmware::State::silent);
  CHECK(talk(fw, "M105\n", Micros{1}).empty());
  CHECK(talk(fw, "G1 X5\n", seconds(3600)).empty());
  CHECK(fw.next_wakeup() == Micros::max());  // nothing to wait for: it never comes back
  CHECK(fw.take_executed() == std::vector<std::string>{"G1 X1", "G1 X2", "G1 X3"});
  CHECK(fw.stats().bytes_ignored == 11);
}

TEST_CASE("silent-for: a stall, what it held runs after it, what came during it is lost") {
  SimFirmware fw = with_faults("silent-after=1,silent-for=5");
  // G1 X2 is queued when the board hangs after G1 X1; G1 X3 arrives during the hang.
  CHECK(talk(fw, "G1 X1\nG1 X2\n", Micros{0}) == "ok\n");
  CHECK(talk(fw, "G1 X3\n", seconds(1)).empty());
  CHECK(fw.next_wakeup() == seconds(5));
  const std::vector<Said> said = run_until(fw, seconds(10));
  REQUIRE(said.size() == 1);
  CHECK(said[0].at == seconds(5));
  CHECK(said[0].text == "ok\n");
  CHECK(talk(fw, "M105\n", seconds(6)).rfind("ok T:", 0) == 0);
  CHECK(fw.take_executed() == std::vector<std::string>{"G1 X1", "G1 X2", "M105"});
  CHECK(fw.stats().bytes_ignored == 6);
  CHECK(fw.state() == SimFirmware::State::running);
}

TEST_CASE("silent-after: no busy, no temperature report and no auto-report from a hung board") {
  SimConfig c;
  c.autoreport = true;
  c.heat_time_scale = 0.01;
  c.faults = parse_faults("silent-after=2");
  SimFirmware fw(c);
  CHECK(talk(fw, "M155 S1\nM109 S200\n", Micros{0}) == "ok\n");  // M109 runs, and is its ok's last
  const std::vector<Said> said = run_until(fw, seconds(5));
  REQUIRE_FALSE(said.empty());
  CHECK(said.back().text.substr(said.back().text.size() - 3) == "ok\n");
  CHECK(fw.state() == SimFirmware::State::silent);
  CHECK(run_until(fw, seconds(60)).empty());
}

TEST_CASE("rerequest: a numbered line that arrived intact is asked for again, once, and runs once") {
  SimFirmware fw = with_faults("rerequest=3");
  CHECK(talk(fw, line(0, "M110 N0") + line(1, "G1 X1"), Micros{0}) == "ok\nok\n");
  // Command 3 is line 2; line 3 behind it goes with the flushed receive buffer.
  CHECK(talk(fw, line(2, "G1 X2") + line(3, "G1 X3"), Micros{1}) == "Resend: 2\nok\n");
  CHECK(talk(fw, line(2, "G1 X2") + line(3, "G1 X3"), Micros{2}) == "ok\nok\n");
  CHECK(fw.take_executed() == std::vector<std::string>{"M110 N0", "G1 X1", "G1 X2", "G1 X3"});
  CHECK(fw.stats().lines_rerequested == 1);
  CHECK(fw.stats().lines_rejected == 0);  // not a line error: nothing was wrong with it
}

TEST_CASE("rerequest: unnumbered lines and M110 cannot be asked for: the next numbered line is") {
  SimFirmware fw = with_faults("rerequest=1,resend-without-ok");
  CHECK(talk(fw, "M115\n", Micros{0}).find("ok\n") != std::string::npos);
  CHECK(talk(fw, line(0, "M110 N0"), Micros{1}) == "ok\n");
  CHECK(talk(fw, line(1, "G1 X1"), Micros{2}) == "Resend: 1\n");  // and resend-without-ok holds
  CHECK(talk(fw, line(1, "G1 X1"), Micros{3}) == "ok\n");
}

TEST_CASE("busy-for: the first command that waits is held, with a keepalive every 2 s") {
  SimFirmware fw = with_faults("busy-for=5");
  CHECK(talk(fw, "G1 X1\nG28\nG1 X2\n", Micros{0}) == "ok\n");
  const std::vector<Said> said = run_until(fw, seconds(60));
  REQUIRE(said.size() == 3);
  CHECK(said[0].at == seconds(2));
  CHECK(said[0].text == "echo:busy: processing\n");
  CHECK(said[1].at == seconds(4));
  CHECK(said[1].text == "echo:busy: processing\n");
  CHECK(said[2].at == seconds(5));
  CHECK(said[2].text == "ok\nok\n");                // G28 (instant at --time-scale 0), then G1 X2
  CHECK(talk(fw, "G28\n", seconds(61)) == "ok\n");  // once only
}

TEST_CASE("busy-at: command N is held, whatever it is") {
  SimFirmware fw = with_faults("busy-at=2,busy-for=1.5");
  CHECK(talk(fw, "G1 X1\nG1 X2\n", Micros{0}) == "ok\n");
  const std::vector<Said> said = run_until(fw, seconds(60));
  REQUIRE(said.size() == 1);  // under 2 s: no keepalive is due
  CHECK(said[0].at == Micros{1500000});
  CHECK(said[0].text == "ok\n");
}

TEST_CASE("malformed-ok: command N's ok arrives with a NUL for its 'k', and no host takes it for an ok") {
  SimFirmware fw = with_faults("malformed-ok=2");
  const std::string garbled("o\0\n", 3);
  CHECK(talk(fw, "G1 X1\nG1 X2\nG1 X3\n", Micros{0}) == "ok\n" + garbled + "ok\n");
  CHECK(fw.stats().oks_malformed == 1);
  namespace marlin = salient::protocol::marlin;
  CHECK(marlin::parse_reply(std::string("o\0", 2)).kind != marlin::ReplyKind::ok);
  CHECK(marlin::parse_reply("o").kind != marlin::ReplyKind::ok);  // a host that drops NULs
  // The ok of M105 carries the temperatures; ADVANCED_OK's carries N, P and B: garbled alike.
  SimConfig c;
  c.advanced_ok = true;
  c.faults = parse_faults("malformed-ok=1");
  SimFirmware ahead(c);
  CHECK(talk(ahead, line(1, "G1 X1"), Micros{0}) == std::string("o\0 N1 P16 B3\n", 13));
  SimFirmware poke = with_faults("malformed-ok=1");
  CHECK(talk(poke, "M105\n", Micros{0}).rfind(std::string("o\0 T:", 5), 0) == 0);
}

TEST_CASE("reset-on-open: the board reboots as the port opens, deaf while it boots") {
  SimFirmware fw = with_faults("reset-on-open,boot-for=0.5");
  fw.boot(Micros{0});
  CHECK(talk(fw, line(1, "G1 X1"), Micros{0}) == kBanner + "ok\n");
  fw.receive("M115\n", seconds(1));
  fw.advance(seconds(1));  // said, never taken: the reset loses it
  fw.port_opened(seconds(1));
  CHECK(fw.state() == SimFirmware::State::booting);
  CHECK(talk(fw, "M105\n", Micros{1100000}).empty());  // the bootloader's: lost
  CHECK(fw.next_wakeup() == Micros{1500000});
  const std::vector<Said> said = run_until(fw, seconds(2));
  REQUIRE(said.size() == 1);
  CHECK(said[0].at == Micros{1500000});
  CHECK(said[0].text == kBanner);
  CHECK(talk(fw, line(1, "G1 X2"), seconds(2)) == "ok\n");  // a fresh line counter
  CHECK(fw.take_executed() == std::vector<std::string>{"G1 X1", "M115", "G1 X2"});
  CHECK(fw.stats().bytes_ignored == 5);
}

TEST_CASE("reset-on-open: a halted board comes back, and without the fault an open changes nothing") {
  SimFirmware fw = with_faults("reset-on-open,boot-for=0,thermal-runaway-at=1");
  talk(fw, "M109 S200\n", Micros{0});
  CHECK(fw.state() == SimFirmware::State::halted);
  fw.port_opened(Micros{1});
  CHECK(fw.state() == SimFirmware::State::running);
  CHECK(fw.take_output(Micros{1}) == kBanner);
  SimFirmware plain({});
  talk(plain, line(1, "G1 X1"), Micros{0});
  plain.port_opened(Micros{1});
  CHECK(talk(plain, line(2, "G1 X2"), Micros{2}) == "ok\n");
}

TEST_CASE("fault specs at a known moment: parsed, and refused by name") {
  const SimFaults f = parse_faults(
      "silent-after=10,silent-for=2.5,rerequest=4,busy-for=3,busy-at=7,malformed-ok=9,reset-on-open,boot-for="
      "0");
  CHECK(f.silent_after == 10);
  CHECK(f.silent_for == doctest::Approx(2.5));
  CHECK(f.rerequest == 4);
  CHECK(f.busy_for == doctest::Approx(3));
  CHECK(f.busy_at == 7);
  CHECK(f.malformed_ok == 9);
  CHECK(f.reset_on_open);
  CHECK(f.boot_for == 0);
  CHECK(parse_faults("reset-on-open").boot_for == doctest::Approx(0.5));
  CHECK_FALSE(parse_faults("reset-on-open=0").reset_on_open);
  using E = std::invalid_argument;
  CHECK_THROWS_WITH_AS(parse_faults("silent-after=0"),
                       "--faults: silent-after must be a positive count of commands", E);
  CHECK_THROWS_WITH_AS(parse_faults("silent-for=3"),
                       "--faults: silent-for needs silent-after=N (the hang it ends)", E);
  CHECK_THROWS_WITH_AS(parse_faults("silent-after=1,silent-for=0"),
                       "--faults: silent-for must be a number of seconds, more than 0 and at most 86400", E);
  CHECK_THROWS_WITH_AS(parse_faults("busy-for=inf"),
                       "--faults: busy-for must be a number of seconds, more than 0 and at most 86400", E);
  CHECK_THROWS_WITH_AS(parse_faults("busy-at=3"),
                       "--faults: busy-at needs busy-for=S (how long command N is held)", E);
  CHECK_THROWS_WITH_AS(parse_faults("rerequest=two"), "--faults: rerequest=two is not a number", E);
  CHECK_THROWS_WITH_AS(parse_faults("malformed-ok"), "--faults: malformed-ok needs a value (malformed-ok=…)",
                       E);
  CHECK_THROWS_WITH_AS(parse_faults("boot-for=1"),
                       "--faults: boot-for needs reset-on-open (the reboot it times)", E);
  CHECK_THROWS_WITH_AS(parse_faults("reset-on-open,boot-for=-1"),
                       "--faults: boot-for must be a number of seconds, from 0 to 86400", E);
  CHECK_THROWS_WITH_AS(parse_faults("reset-on-open=yes"), "--faults: reset-on-open=yes is not a number", E);
  CHECK(faults_help().find("silent-after=N") != std::string_view::npos);
}
