// SimFirmware driven directly (no pseudo-terminal): what Marlin would answer, byte for byte.
#include "protocol/sim/sim_firmware.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <stdexcept>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/sim/sim_faults.hpp"
#include "protocol/sim/wire.hpp"

using namespace salient::protocol::sim;
using salient::protocol::marlin::frame;

namespace {

std::string line(long long n, const std::string& command) {
  return frame(static_cast<std::uint64_t>(n), command) + "\n";
}

// Feeds `bytes` at `t`, runs the firmware and returns what it said.
std::string talk(SimFirmware& fw, const std::string& bytes, Micros t) {
  fw.receive(bytes, t);
  fw.advance(t);
  return fw.take_output(t);
}

}  // namespace

TEST_CASE("numbered lines are checked in Marlin's order and a bad one flushes the buffer") {
  SimFirmware fw({});
  const Micros t{0};
  CHECK(talk(fw, line(0, "M110 N0") + line(1, "G1 X1"), t) == "ok\nok\n");
  // Line 2 arrives corrupted; line 3 behind it is flushed with the receive buffer.
  std::string bad = line(2, "G1 X2");
  bad[4] = 'Y';
  CHECK(talk(fw, bad + line(3, "G1 X3"), t) == "Error:checksum mismatch, Last Line: 1\nResend: 2\nok\n");
  CHECK(talk(fw, line(3, "G1 X3"), t) ==
        "Error:Line Number is not Last Line Number+1, Last Line: 1\nResend: 2\nok\n");
  CHECK(talk(fw, "N2 G1 X2\n", t) == "Error:No Checksum with line number, Last Line: 1\nResend: 2\nok\n");
  CHECK(talk(fw, line(2, "G1 X2") + line(3, "G1 X3") + "G1 X4 ; unnumbered\n", t) == "ok\nok\nok\n");
  CHECK(fw.take_executed() == std::vector<std::string>{"M110 N0", "G1 X1", "G1 X2", "G1 X3", "G1 X4"});
  CHECK(fw.stats().lines_rejected == 3);
}

TEST_CASE("ADVANCED_OK names the line and the free planner blocks and queue slots") {
  SimConfig c;
  c.advanced_ok = true;
  SimFirmware fw(c);
  CHECK(talk(fw, line(0, "M110 N0"), Micros{0}) == "ok N0 P16 B3\n");
  CHECK(talk(fw, "M115\n", Micros{0}).find("Cap:EMERGENCY_PARSER:0\nCap:EEPROM:0\nok P16 B3\n") !=
        std::string::npos);
}

TEST_CASE("moves take planner blocks and time, the queue holds BUFSIZE commands, oks follow") {
  SimConfig c;
  c.time_scale = 1;
  c.planner_blocks = 2;
  c.acceleration = 1000;
  SimFirmware fw(c);
  // 100 mm at 100 mm/s with 1000 mm/s²: 1.1 s each (a trapezoid from and to rest).
  std::string bytes;
  for (int i = 1; i <= 6; ++i) bytes += "G1 X" + std::to_string(100 * i) + " F6000\n";
  CHECK(talk(fw, bytes, Micros{0}) == "ok\nok\n");  // two blocks in the planner, the third waits
  CHECK(fw.next_wakeup() == Micros{1100000});
  fw.advance(Micros{1100000});
  CHECK(fw.take_output(Micros{1100000}) == "ok\n");
  fw.advance(Micros{2200000});
  CHECK(fw.take_output(Micros{2200000}) == "ok\n");
  CHECK(fw.take_executed().size() == 4);
  // M400 waits for every move to finish.
  CHECK(talk(fw, "M400\n", Micros{2200000}).empty());
  std::string said;
  Micros t{2200000};
  auto oks = [&] { return std::count(said.begin(), said.end(), 'k'); };
  while (oks() < 3 && t < Micros{60000000}) {
    t = fw.next_wakeup();
    fw.advance(t);
    said += fw.take_output(t);
  }
  CHECK(said == "ok\nok\necho:busy: processing\nok\n");  // M400 waited over 2 s: a keepalive
  CHECK(t == Micros{6600000});                           // moves 5 and 6 entered as blocks 3 and 4 finished
}

TEST_CASE("an arc takes the time of its length along the arc, not of its chord") {
  SimConfig c;
  c.time_scale = 1;
  c.planner_blocks = 1;  // the next move waits for the arc to finish
  c.acceleration = 1000;
  SimFirmware fw(c);
  // A half circle of r 50 from (0,0) round (50,0) to (100,0): 157.08 mm at 100 mm/s, so
  // 157.08 / 100 + 100 / 1000 = 1.6708 s (its 100 mm chord would take 1.1 s).
  CHECK(talk(fw, "G3 X100 Y0 I50 J0 F6000\nG2 X0 Y0 I-50 J0\n", Micros{0}) == "ok\n");
  CHECK(fw.next_wakeup().count() == doctest::Approx(1670796).epsilon(1e-4));
  fw.advance(fw.next_wakeup());
  CHECK(fw.take_output(fw.next_wakeup()) == "ok\n");
  // Clockwise back round the same circle: as long again.
  CHECK(talk(fw, "G1 X0 Y0\n", Micros{1670796}).empty());
  CHECK(fw.next_wakeup().count() == doctest::Approx(2 * 1670796).epsilon(1e-4));
}

TEST_CASE("M109 waits for the heater, with busy keepalives and temperature reports") {
  SimConfig c;
  c.heat_time_scale = 0.01;  // 3 °C/s: 21 → 210 °C takes 63 printer s, 0.63 wall s
  SimFirmware fw(c);
  CHECK(talk(fw, "M109 S210\n", Micros{0}).empty());
  std::string said;
  for (Micros t{0}; t < Micros{1000000}; t += Micros{5000}) {
    fw.advance(t);
    said += fw.take_output(t);
  }
  CHECK(said.find("echo:busy: processing") != std::string::npos);  // every 2 printer s: 20 ms here
  CHECK(said.find(" /210.00") != std::string::npos);
  CHECK(said.substr(said.size() - 3) == "ok\n");
  CHECK(talk(fw, "M105\n", Micros{1000000}).rfind("ok T:210.00 /210.00", 0) == 0);
}

TEST_CASE("the emergency parser acts on M112 at once, even behind a full queue") {
  SimConfig c;
  c.emergency_parser = true;
  c.time_scale = 1;
  SimFirmware fw(c);
  std::string bytes = "M109 S200\nG1 X1\nG1 X2\nG1 X3\nM112\n";
  CHECK(talk(fw, bytes, Micros{0}) == "Error:Printer halted. kill() called!\n");
  CHECK(fw.state() == SimFirmware::State::halted);
  talk(fw, "G1 X5\n", Micros{1});
  CHECK(fw.stats().lines_after_halt == 1);
  SimFirmware slow({});  // without the parser M112 waits its turn
  CHECK(talk(slow, "G1 X1\nM112\n", Micros{0}) == "ok\nError:Printer halted. kill() called!\n");
}

TEST_CASE("the receive buffer drops what does not fit") {
  SimConfig c;
  c.rx_buffer_bytes = 32;
  c.bufsize = 4;
  c.time_scale = 1;
  c.planner_blocks = 1;
  SimFirmware fw(c);
  std::string bytes;
  for (int i = 0; i < 10; ++i) bytes += "G1 X" + std::to_string(10 * i + 10) + " F600\n";
  talk(fw, bytes, Micros{0});
  CHECK(fw.stats().rx_overflow_bytes > 0);
}

TEST_CASE("faults: reset, thermal runaway, disconnect, no ok after Resend, dropped oks") {
  SimConfig c;
  c.faults = parse_faults("reset-after=2");
  SimFirmware r(c);
  CHECK(talk(r, "G1 X1\nG1 X2\nG1 X3\n", Micros{0}).find("ok\nstart\n") == 0);
  c.faults = parse_faults("thermal-runaway-at=1");
  SimFirmware t(c);
  CHECK(talk(t, "G1 X1\n", Micros{0}) ==
        "Error:Thermal Runaway, system stopped! Heater_ID: 0\nError:Printer halted. kill() called!\n");
  c.faults = parse_faults("disconnect-after=1");
  SimFirmware d(c);
  talk(d, "G1 X1\n", Micros{0});
  CHECK(d.state() == SimFirmware::State::disconnected);
  c.faults = parse_faults("resend-without-ok");
  SimFirmware n(c);
  CHECK(talk(n, line(5, "G1 X1"), Micros{0}) ==
        "Error:Line Number is not Last Line Number+1, Last Line: 0\nResend: 1\n");
  c.faults = parse_faults("drop-ok=1");
  SimFirmware o(c);
  CHECK(talk(o, "G1 X1\nG1 X2\n", Micros{0}).empty());
  CHECK(o.stats().oks_dropped == 2);
}

TEST_CASE("noise corrupts lines, never undetectably") {
  SimConfig c;
  c.faults = parse_faults("noise=0.5,seed=7");
  SimFirmware fw(c);
  long long n = 0;
  Micros t{0};
  for (int i = 0; i < 2000; ++i) {
    const std::string said = talk(fw, line(n + 1, "G1 X" + std::to_string(i) + " Y2 E0.5"), t += Micros{1});
    if (said == "ok\n") ++n;
  }
  const auto executed = fw.take_executed();
  CHECK(fw.stats().lines_corrupted > 500);
  CHECK(static_cast<long long>(executed.size()) == n);
  for (std::size_t k = 0; k < executed.size(); ++k) CHECK(executed[k].rfind("G1 X", 0) == 0);
}

TEST_CASE("fault specs: values checked, unknown names refused with the list") {
  const SimFaults f = parse_faults("noise=0.02,drop-ok=0.01,resend-without-ok,disconnect-after=5000,seed=3");
  CHECK(f.noise == doctest::Approx(0.02));
  CHECK(f.drop_ok == doctest::Approx(0.01));
  CHECK(f.resend_without_ok);
  CHECK(f.disconnect_after == 5000);
  CHECK(f.seed == 3);
  CHECK_THROWS_WITH_AS(parse_faults("noise=2"), "--faults: noise must be between 0 and 1",
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(parse_faults("reset-after=x"), "--faults: reset-after=x is not a number",
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(parse_faults("noise"), "--faults: noise needs a value (noise=…)",
                       std::invalid_argument);
  CHECK_THROWS_AS(parse_faults("explode=1"), std::invalid_argument);
}

TEST_CASE("wire: bytes arrive at the line rate, one after another") {
  Wire w(25000);  // 250,000 baud: 40 µs a byte
  w.push("0123456789", Micros{0});
  CHECK(w.pop(Micros{39}).empty());
  CHECK(w.pop(Micros{40}) == "0");
  CHECK(w.next_arrival() == Micros{80});
  CHECK(w.last_arrival() == Micros{400});
  w.push("ab", Micros{100});  // queued behind the first ten bytes
  CHECK(w.last_arrival() == Micros{480});
  CHECK(w.pop(Micros{400}) == "123456789");
  CHECK(w.pop(Micros{440}) == "a");
  CHECK(w.pop(Micros{10000}) == "b");
  CHECK(w.last_arrival() == Micros::max());
  Wire fast;
  fast.push("xyz", Micros{5});
  CHECK(fast.pop(Micros{5}) == "xyz");
}
