// MarlinSession in scripted conversations: what it writes, given what the firmware answers.
#include "protocol/marlin/marlin_session.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <deque>
#include <sstream>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/marlin/marlin_reply.hpp"

using namespace salient::protocol::marlin;
using std::chrono::milliseconds;

namespace {

// The numbered commands in `output`, as (line, command), checking each checksum.
std::vector<std::pair<long long, std::string>> sent(const std::string& output) {
  std::vector<std::pair<long long, std::string>> out;
  std::istringstream in(output);
  std::string line;
  while (std::getline(in, line)) {
    FrameError e;
    const FramedLine f = parse_frame(line, e);
    REQUIRE(e == FrameError::none);
    if (f.number) out.emplace_back(static_cast<long long>(*f.number), f.command);
  }
  return out;
}

const std::vector<std::string> program = {"G28 ; home", "", "G1 X10 Y10 F3000", "M104 S200", "G1 X20"};

}  // namespace

TEST_CASE("ping-pong: one line at a time, comments and blank lines dropped, finished at the end") {
  MarlinSession s;
  s.begin(program, milliseconds(0));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{0, "M110 N0"}});
  std::vector<std::string> commands;
  for (int i = 0; i < 5; ++i) {
    s.on_receive("ok\n", milliseconds(10 * i));
    for (const auto& [n, c] : sent(s.take_output())) commands.push_back(c);
  }
  CHECK(commands == std::vector<std::string>{"G28", "G1 X10 Y10 F3000", "M104 S200", "G1 X20"});
  CHECK(s.state() == SessionState::finished);
  CHECK(s.commands_done() == 4);
  CHECK(s.commands_total() == 4);
}

TEST_CASE("ADVANCED_OK: send ahead up to the free slots, within the receive buffer") {
  SessionConfig c;
  c.rx_buffer_bytes = 64;
  MarlinSession s(c);
  std::vector<std::string> many(20, "G1 X1 Y1");
  s.begin(many, milliseconds(0));
  s.take_output();
  s.on_receive("ok N0 P15 B3\n", milliseconds(1));
  CHECK(s.advanced_ok());
  const auto burst = sent(s.take_output());
  CHECK(burst.size() == 3);                          // B3 free slots; 3 × 18 bytes fits 64
  s.on_receive("ok N1 P15 B16\n", milliseconds(2));  // line 1 done: lines 2 and 3 still in flight
  const auto more = sent(s.take_output());
  std::size_t bytes = 0;
  for (std::size_t k = 1; k < burst.size(); ++k)
    bytes += frame(static_cast<std::uint64_t>(burst[k].first), burst[k].second).size() + 1;
  for (const auto& [n, cmd] : more) bytes += frame(static_cast<std::uint64_t>(n), cmd).size() + 1;
  CHECK(more.size() >= 1);
  CHECK(bytes <= 64);  // never more bytes in flight than the buffer holds
}

TEST_CASE("Resend: rewind once, ignore the repeats, keep going, nothing lost or doubled") {
  MarlinSession s;
  s.begin({"G1 X1", "G1 X2", "G1 X3", "G1 X4"}, milliseconds(0));
  s.take_output();
  s.on_receive("ok N0 P15 B4\n", milliseconds(1));  // lines 1..4 go out
  CHECK(sent(s.take_output()).size() == 4);
  s.on_receive("ok N1 P15 B3\n", milliseconds(2));  // line 1 done; line 2 arrived corrupted:
  s.on_receive("Error:checksum mismatch, Last Line: 1\nResend: 2\nok\n", milliseconds(3));
  const auto again = sent(s.take_output());
  REQUIRE(!again.empty());
  CHECK(again.front() == std::pair<long long, std::string>{2, "G1 X2"});
  // Lines 3 and 4 were discarded by the firmware and each draws the same request: ignored.
  s.on_receive("Error:Line Number is not Last Line Number+1, Last Line: 1\nResend: 2\nok\n", milliseconds(4));
  s.on_receive("Error:Line Number is not Last Line Number+1, Last Line: 1\nResend: 2\nok\n", milliseconds(5));
  std::vector<std::pair<long long, std::string>> all = again;
  for (const auto& x : sent(s.take_output())) all.push_back(x);
  CHECK(all == std::vector<std::pair<long long, std::string>>{{2, "G1 X2"}, {3, "G1 X3"}, {4, "G1 X4"}});
  s.on_receive("ok N2 P15 B3\n", milliseconds(10));
  CHECK(s.commands_done() == 2);
  s.on_receive("ok\n", milliseconds(11));  // ADVANCED_OK firmware's plain ok: acknowledges nothing
  CHECK(s.commands_done() == 2);
  s.on_receive("ok N4 P15 B3\n", milliseconds(12));  // line 3's ok was lost: N4 settles both
  CHECK(s.commands_done() == 4);
  CHECK(s.state() == SessionState::finished);
}

TEST_CASE("a line rejected again and again ends the print with a reason") {
  MarlinSession s;
  s.begin({"G1 X1"}, milliseconds(0));
  s.take_output();
  s.on_receive("ok\n", milliseconds(1));
  s.take_output();
  for (int i = 0; i < 6; ++i) {
    s.on_receive("Error:checksum mismatch\nResend: 1\nok\n", milliseconds(2 + i));
    s.take_output();
  }
  CHECK(s.state() == SessionState::failed);
  bool said = false;
  for (const auto& e : s.take_events())
    if (e.kind == SessionEvent::Kind::failed) said = e.text.find("rejected 5 times") != std::string::npos;
  CHECK(said);
}

TEST_CASE("firmware that sends no ok after Resend") {
  SessionConfig c;
  c.ok_after_resend = SessionConfig::OkAfterResend::no;
  MarlinSession s(c);
  s.begin({"G1 X1", "G1 X2"}, milliseconds(0));
  s.take_output();
  s.on_receive("ok\n", milliseconds(1));
  s.take_output();  // line 1
  s.on_receive("Resend: 1\n", milliseconds(2));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{1, "G1 X1"}});
  s.on_receive("ok\nok\n", milliseconds(3));
  CHECK(s.commands_done() == 2);
}

TEST_CASE("ping-pong: the ok after a Resend is waited for, and its absence is learnt") {
  SessionConfig c;
  c.resend_ok_wait = milliseconds(100);
  MarlinSession s(c);
  std::vector<std::string> program(6, "G1 X1");
  s.begin(program, milliseconds(0));
  s.take_output();
  s.on_receive("ok\n", milliseconds(1));
  s.take_output();  // line 1
  // Marlin's order: Resend, then ok. The resent line waits for that ok, which acknowledges nothing.
  s.on_receive("Error:checksum mismatch, Last Line: 0\nResend: 1\n", milliseconds(2));
  CHECK(sent(s.take_output()).empty());
  s.on_receive("ok\n", milliseconds(3));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{1, "G1 X1"}});
  CHECK(s.commands_done() == 0);
  s.on_receive("ok\n", milliseconds(4));
  CHECK(s.commands_done() == 1);
}

TEST_CASE("ping-pong: a firmware that sends no ok after Resend is learnt after two requests") {
  SessionConfig c;
  c.resend_ok_wait = milliseconds(100);
  MarlinSession s(c);
  std::vector<std::string> program(6, "G1 X1");
  s.begin(program, milliseconds(0));
  s.on_receive("ok\n", milliseconds(1));
  s.take_output();  // line 1
  for (int round = 0; round < 2; ++round) {
    const long long line = 1 + round;
    const Millis t = milliseconds(1000 * (round + 1));
    s.on_receive("Error:checksum mismatch\nResend: " + std::to_string(line) + "\n", t);
    CHECK(sent(s.take_output()).empty());
    s.on_tick(t + milliseconds(100));  // no ok came: the line goes anyway
    CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{line, "G1 X1"}});
    s.on_receive("ok\n", t + milliseconds(101));
    s.take_output();
  }
  CHECK(s.commands_done() == 2);
  // Twice without an ok and never one seen: from now on the resent line goes at once.
  s.on_receive("Error:checksum mismatch\nResend: 3\n", milliseconds(5000));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{3, "G1 X1"}});
}

TEST_CASE("a checksum error on the resent line is not taken for a repeat") {
  MarlinSession s;
  s.begin({"G1 X1", "G1 X2", "G1 X3"}, milliseconds(0));
  s.take_output();
  s.on_receive("ok N0 P15 B3\n", milliseconds(1));  // lines 1..3 go out
  CHECK(sent(s.take_output()).size() == 3);
  s.on_receive("Error:checksum mismatch, Last Line: 0\nResend: 1\nok\n", milliseconds(2));
  CHECK(sent(s.take_output()).size() == 3);  // 1..3 again; lines 2 and 3 will draw repeats
  s.on_receive("Error:Line Number is not Last Line Number+1, Last Line: 0\nResend: 1\nok\n", milliseconds(3));
  CHECK(sent(s.take_output()).empty());  // a repeat
  s.on_receive("Error:checksum mismatch, Last Line: 0\nResend: 1\nok\n", milliseconds(4));
  CHECK(sent(s.take_output()).size() == 3);  // the resent line 1 itself failed: genuine
}

TEST_CASE("silence: a poke after the timeout, busy extends it, the poke's ok settles lost oks") {
  SessionConfig c;
  c.reply_timeout = milliseconds(1000);
  c.busy_timeout = milliseconds(5000);
  MarlinSession s(c);
  s.begin({"M109 S200", "G1 X1"}, milliseconds(0));
  s.on_receive("ok\n", milliseconds(10));  // M110 done, M109 sent
  s.take_output();
  s.on_receive("echo:busy: processing\n", milliseconds(900));
  s.on_tick(milliseconds(2000));
  CHECK(s.take_output().empty());  // busy: still waiting
  s.on_tick(milliseconds(6000));
  const auto poke = sent(s.take_output());
  REQUIRE(poke.size() == 1);
  CHECK(poke[0].second == "M105");
  s.on_receive("ok T:200.0 /200.0 B:60.0 /60.0 @:0 B@:0\n", milliseconds(6100));  // the M109 ok was lost
  CHECK(s.commands_done() == 1);
  const auto next = sent(s.take_output());
  REQUIRE(next.size() == 1);
  CHECK(next[0].second == "G1 X1");
}

TEST_CASE("a reset or a fatal error ends the print, other errors are reported") {
  MarlinSession s;
  s.begin({"G1 X1", "G1 X2"}, milliseconds(0));
  s.on_receive("Error:Printer halted. kill() called!\n", milliseconds(1));
  CHECK(s.state() == SessionState::failed);
  MarlinSession r;
  r.begin({"G1 X1"}, milliseconds(0));
  r.on_receive("start\n", milliseconds(1));
  CHECK(r.state() == SessionState::failed);
  MarlinSession e;
  e.begin({"G1 X1"}, milliseconds(0));
  e.on_receive("Error:Unknown command: \"G999\"\n", milliseconds(1));
  CHECK(e.state() == SessionState::printing);
}

TEST_CASE("pause, resume, cancel and emergency stop") {
  MarlinSession s;
  s.begin({"G1 X1", "G1 X2", "G1 X3"}, milliseconds(0));
  s.take_output();
  s.pause();
  s.on_receive("ok\n", milliseconds(1));
  CHECK(sent(s.take_output()).empty());  // paused: nothing more goes out
  s.resume(milliseconds(2));
  CHECK(sent(s.take_output()).size() == 1);
  s.cancel({"M104 S0", "M140 S0 ; heaters off"}, milliseconds(3));
  s.on_receive("ok\n", milliseconds(4));
  auto cleanup = sent(s.take_output());
  REQUIRE(cleanup.size() == 1);
  CHECK(cleanup[0].second == "M104 S0");
  CHECK(s.state() == SessionState::cancelled);
  s.emergency_stop();
  CHECK(s.take_output() == "M112\n");
  CHECK(s.state() == SessionState::failed);
}

TEST_CASE(
    "console lines during a print: next to go, while paused too, not counted, before a cancel's cleanup") {
  MarlinSession s;  // ping-pong: one line in flight, so the order is plain to see
  s.begin(program, milliseconds(0));
  s.take_output();                        // M110 N0
  s.on_receive("ok\n", milliseconds(1));  // G28 goes
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{1, "G28"}});
  s.send_now({"M106 S128 ; fan", "", "M220 S90"}, milliseconds(2));  // waits for the line in flight
  CHECK(s.take_output().empty());
  s.on_receive("ok\n", milliseconds(3));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{2, "M106 S128"}});
  s.pause();
  s.on_receive("ok\n", milliseconds(4));  // paused: the console line still goes, the program's does not
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{3, "M220 S90"}});
  s.on_receive("ok\n", milliseconds(5));
  CHECK(s.take_output().empty());
  s.send_now({"M104 S190"}, milliseconds(6));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{4, "M104 S190"}});
  s.on_receive("ok\n", milliseconds(7));
  CHECK(s.commands_done() == 1);  // only G28 of the file
  s.resume(milliseconds(8));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{5, "G1 X10 Y10 F3000"}});
  s.send_now({"M107", "M104 S200"}, milliseconds(9));  // waiting behind the move…
  s.cancel({"M104 S0"}, milliseconds(10));  // …still go, before the cleanup (which turns the heater off)
  s.on_receive("ok\n", milliseconds(11));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{6, "M107"}});
  s.on_receive("ok\n", milliseconds(12));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{7, "M104 S200"}});
  s.on_receive("ok\n", milliseconds(13));
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{8, "M104 S0"}});
  CHECK(!s.idle());
  s.on_receive("ok\n", milliseconds(14));
  CHECK(s.state() == SessionState::cancelled);
  CHECK(s.idle());
  s.send_now({"M106"}, milliseconds(15));  // nothing goes after the end
  CHECK(s.take_output().empty());
}

TEST_CASE("replies: temperatures, firmware, capabilities, host actions, split across reads") {
  MarlinReply t = parse_reply(" T:210.5 /215.0 B:60.2 /60.0 @:127 B@:0");
  CHECK(t.kind == ReplyKind::temperature);
  CHECK(*t.temperatures.hotend == 210.5);
  CHECK(*t.temperatures.hotend_target == 215.0);
  CHECK(*t.temperatures.bed == doctest::Approx(60.2));
  CHECK(*t.temperatures.bed_target == 60.0);
  MarlinReply f =
      parse_reply("FIRMWARE_NAME:Marlin 2.1.2 (Jan 1 2024) SOURCE_CODE_URL:github.com/MarlinFirmware/Marlin");
  CHECK(f.name == "Marlin 2.1.2 (Jan 1 2024)");
  MarlinReply cap = parse_reply("Cap:EMERGENCY_PARSER:1");
  CHECK(cap.kind == ReplyKind::capability);
  CHECK(cap.name == "EMERGENCY_PARSER");
  CHECK(cap.enabled);
  CHECK(parse_reply("//action:pause").name == "pause");
  CHECK(parse_reply("rs N7").line == 7);
  CHECK(parse_reply("Error:Thermal Runaway, system stopped! Heater_ID: 0").fatal);
  MarlinSession s;
  s.begin({"G1 X1"}, milliseconds(0));
  s.on_receive("o", milliseconds(1));
  s.on_receive("k\nT:20", milliseconds(2));
  s.on_receive("0.0 /200.0\n", milliseconds(3));
  bool temps = false;
  for (const auto& e : s.take_events())
    temps = temps || (e.kind == SessionEvent::Kind::temperatures && *e.temperatures.hotend == 200.0);
  CHECK(temps);
}

TEST_CASE("a poke whose own ok is lost: the next poke's reply settles both, nothing stays in flight") {
  SessionConfig c;
  c.reply_timeout = milliseconds(100);
  MarlinSession s(c);
  s.begin({"G1 X1", "G1 X2"}, milliseconds(0));
  s.on_receive("ok\n", milliseconds(1));
  s.take_output();               // line 1 goes; its ok is lost
  s.on_tick(milliseconds(200));  // poke 1 (line 2); its ok is lost too
  s.on_tick(milliseconds(400));  // poke 2 (line 3)
  const auto pokes = sent(s.take_output());
  REQUIRE(pokes.size() == 2);
  s.on_receive("ok T:200.0 /200.0 B:60.0 /60.0 @:0 B@:0\n", milliseconds(401));
  CHECK(s.commands_done() == 1);
  CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{4, "G1 X2"}});
  s.on_receive("ok\n", milliseconds(402));
  CHECK(s.state() == SessionState::finished);
  CHECK(s.pokes_sent() == 2);
}

namespace {

// Drives a ping-pong print against a firmware that answers each line `latency` after it was
// sent and loses the oks named in `lost` (counting lines that are not pokes), ticking every
// millisecond as a driver does; returns the time the print took.
milliseconds run_ping_pong(std::size_t lines, milliseconds latency, const std::vector<std::size_t>& lost,
                           std::size_t* pokes = nullptr) {
  std::vector<std::string> gcode;
  for (std::size_t i = 0; i < lines; ++i)
    gcode.push_back("G1 X" + std::to_string(i % 2) + " F6000");  // 1 mm moves
  MarlinSession s;
  milliseconds now(0);
  s.begin(gcode, now);
  std::deque<std::pair<milliseconds, std::string>> replies;  // due time, reply
  std::size_t answered = 0;
  while (s.state() == SessionState::printing && now < milliseconds(10'000'000)) {
    for (const auto& [n, c] : sent(s.take_output())) {
      if (c == "M105")
        replies.emplace_back(now + latency, "ok T:200.0 /200.0\n");
      else if (std::find(lost.begin(), lost.end(), answered++) == lost.end())
        replies.emplace_back(now + latency, "ok\n");
    }
    now += milliseconds(1);
    while (!replies.empty() && replies.front().first <= now) {
      s.on_receive(replies.front().second, now);
      replies.pop_front();
    }
    s.on_tick(now);
  }
  REQUIRE(s.state() == SessionState::finished);
  if (pokes) *pokes = s.pokes_sent();
  return now;
}

}  // namespace

TEST_CASE("a lost ok in ping-pong costs a fraction of a second, adapted to the link, not the 10 s ceiling") {
  const milliseconds clean = run_ping_pong(2000, milliseconds(5), {});
  std::vector<std::size_t> lost;
  for (std::size_t i = 100; i < 2000; i += 100) lost.push_back(i);  // 1 % of the oks, 19 of them
  std::size_t pokes = 0;
  const milliseconds lossy = run_ping_pong(2000, milliseconds(5), lost, &pokes);
  CHECK(pokes == lost.size());
  const double per_loss = double((lossy - clean).count()) / double(lost.size());
  // min_reply_timeout (250 ms) + the least time of a 1 mm move (89 ms at 500 mm/s²) + the poke's round trip
  CHECK(per_loss <= 400);
  // A printer that is merely slow (1.5 s per line, steadily) is learned, and never poked.
  std::size_t slow_pokes = 0;
  run_ping_pong(60, milliseconds(1500), {}, &slow_pokes);
  CHECK(slow_pokes == 0);
}

TEST_CASE("a printer that goes silent fails the print after silence_limit, naming the last confirmed line") {
  SessionConfig c;
  c.silence_limit = milliseconds(5000);
  MarlinSession s(c);
  s.begin({"G1 X1", "G1 X2", "G1 X3"}, milliseconds(0));
  s.on_receive("ok\n", milliseconds(5));   // M110
  s.on_receive("ok\n", milliseconds(10));  // G1 X1; then nothing ever again
  milliseconds now(10);
  while (s.state() == SessionState::printing && now < milliseconds(60000)) s.on_tick(now += milliseconds(50));
  CHECK(s.state() == SessionState::failed);
  CHECK(now >= milliseconds(5000));
  CHECK(now <= milliseconds(5100));
  CHECK(s.pokes_sent() >= 2);
  CHECK(s.pokes_sent() <= 6);  // backing off: 250 ms, then doubling up to poke_interval
  CHECK(s.commands_done() == 1);
  bool said = false;
  for (const auto& e : s.take_events())
    if (e.kind == SessionEvent::Kind::failed)
      said = e.text.find("stopped answering after line 1") != std::string::npos;
  CHECK(said);
}

TEST_CASE("a cancel that a silent printer never confirms ends after cancel_silence_limit") {
  SessionConfig c;
  c.cancel_silence_limit = milliseconds(2000);
  MarlinSession s(c);
  s.begin({"G1 X1", "G1 X2"}, milliseconds(0));
  s.on_receive("ok\n", milliseconds(5));
  s.cancel({"M104 S0"}, milliseconds(100));
  milliseconds now(100);
  while (s.state() == SessionState::cancelled && now < milliseconds(60000))
    s.on_tick(now += milliseconds(50));
  CHECK(s.state() == SessionState::failed);
  CHECK(now <= milliseconds(2200));
}

TEST_CASE("cancel during a heating wait: M108 at once with an emergency parser, M112 without one") {
  for (bool parser : {true, false}) {
    CAPTURE(parser);
    SessionConfig c;
    c.emergency_parser = parser;
    MarlinSession s(c);
    s.begin({"M109 S200", "G1 X1"}, milliseconds(0));
    s.on_receive("ok\n", milliseconds(5));  // M110 done; M109 goes and waits for the heat
    s.take_output();
    s.cancel({"M104 S0"}, milliseconds(100));
    const std::string out = s.take_output();
    CHECK(s.halted() == !parser);
    if (parser) {  // numbered: Marlin queues it too, and its ok must not settle another line
      CHECK(sent(out) == std::vector<std::pair<long long, std::string>>{{2, "M108"}});
      s.on_tick(milliseconds(700));  // still waiting (M109 may not have begun): again
      CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{3, "M108"}});
      s.on_receive("ok\nok\nok\n", milliseconds(710));  // M109 broken off, then both M108s
      CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{4, "M104 S0"}});
      s.on_tick(milliseconds(1250));  // past the next M108's time, within the reply timeout
      CHECK(s.take_output() == "");   // no heating wait in flight: no more M108
    } else {
      CHECK(out.rfind("M112\n", 0) == 0);
      CHECK(s.state() == SessionState::failed);
    }
  }
}

TEST_CASE("an empty file finishes at once, an unsendable line is refused before anything goes") {
  MarlinSession empty;
  empty.begin({"; only a comment", ""}, milliseconds(0));
  empty.on_receive("ok\n", milliseconds(1));  // M110
  CHECK(empty.state() == SessionState::finished);
  MarlinSession binary;
  binary.begin({"G28", std::string("G1 X1\0\x01\xff", 9)}, milliseconds(0));
  CHECK(binary.state() == SessionState::failed);
  CHECK(binary.take_output().empty());
  MarlinSession long_line;
  long_line.begin({"M117 " + std::string(100, 'a')}, milliseconds(0));
  CHECK(long_line.state() == SessionState::failed);
  const auto bad = find_unsendable({"G28", "", "G1 X1 ; fine", "G1 X2*3"});
  REQUIRE(bad);
  CHECK(bad->line == 4);
  CHECK(unsendable("G1 X\xc3\xa9").find("not printable ASCII") != std::string::npos);
}

TEST_CASE("a corrupted M110 N0 is sent again, whatever line the firmware then asks for") {
  for (const char* reply :
       {"Error:checksum mismatch, Last Line: 8921\nResend: 8922\nok\n",  // after another print
        "Error:checksum mismatch, Last Line: 0\nResend: 1\nok\n"}) {     // after a connect
    CAPTURE(reply);
    MarlinSession s;
    s.begin({"G1 X1", "G1 X2"}, milliseconds(0));
    CHECK(sent(s.take_output()) == std::vector<std::pair<long long, std::string>>{{0, "M110 N0"}});
    s.on_receive(reply, milliseconds(5));
    CHECK(s.state() == SessionState::printing);
    CHECK(sent(s.take_output()) ==
          std::vector<std::pair<long long, std::string>>{{0, "M110 N0"}});  // at once
    for (int i = 0; i < 3; ++i) s.on_receive("ok\n", milliseconds(10 + i));
    CHECK(s.state() == SessionState::finished);
    CHECK(s.commands_done() == 2);
  }
}

// Issue 32: a node paused for 15 s (SIGSTOP, a suspended VM) sent no poll meanwhile, and on
// waking called its idle printer dead. Only time the host was there to hear counts as silence.
TEST_CASE(
    "a host away longer than the silence limit does not call its printer gone, but silence while it looks "
    "does") {
  SessionConfig config;
  config.idle_poll = milliseconds(2000);
  config.idle_silence_limit = milliseconds(15000);
  MarlinSession s(config);
  s.on_tick(milliseconds(0));
  s.on_receive("ok T:20.5 /0.0 B:21.0 /0.0\n", milliseconds(50));
  s.on_tick(milliseconds(100));
  s.on_tick(milliseconds(20100));  // the host was stopped for 20 s: no poll went, nothing read
  for (const auto& e : s.take_events()) CHECK(e.kind != SessionEvent::Kind::timeout);
  CHECK(s.take_output().find("M105") != std::string::npos);  // it asks again at once
  // Now looking every 100 ms and hearing nothing: gone 15 s after the last byte, less the 20 s away.
  int lost_at = 0;
  for (int t = 20200; t <= 40000 && !lost_at; t += 100) {
    s.on_tick(milliseconds(t));
    for (const auto& e : s.take_events())
      if (e.kind == SessionEvent::Kind::timeout) lost_at = t;
  }
  CHECK(lost_at > 35000);
  CHECK(lost_at <= 35200);
}

TEST_CASE("between prints a session listens: polls, temperatures, errors, a restart, and silence once") {
  SessionConfig config;
  config.idle_poll = milliseconds(2000);
  config.idle_silence_limit = milliseconds(15000);
  MarlinSession s(config);
  s.on_tick(milliseconds(0));
  CHECK(s.take_output() == "M105\n");  // unnumbered
  s.on_tick(milliseconds(1000));
  CHECK(s.take_output().empty());  // not yet
  s.on_receive("ok T:20.5 /0.0 B:21.0 /60.0\nError:Heating failed\nstart\necho:busy\n", milliseconds(1500));
  const auto events = s.take_events();
  REQUIRE(events.size() == 3);
  CHECK(events[0].kind == SessionEvent::Kind::temperatures);
  CHECK(events[0].temperatures.bed_target == 60.0);
  CHECK(events[1].kind == SessionEvent::Kind::error);
  CHECK(events[1].text.find("Heating failed") != std::string::npos);
  CHECK(events[2].kind == SessionEvent::Kind::reset);
  s.on_tick(milliseconds(2000));
  CHECK(s.take_output() == "M105\n");
  for (int t = 2100; t <= 16000; t += 100) s.on_tick(milliseconds(t));  // the drivers tick often
  s.take_output();                                                      // the polls
  // 14.5 s since the last byte: still there
  for (const auto& e : s.take_events()) CHECK(e.kind != SessionEvent::Kind::timeout);
  s.on_tick(milliseconds(16600));
  const auto lost = s.take_events();
  REQUIRE(lost.size() == 1);
  CHECK(lost[0].kind == SessionEvent::Kind::timeout);
  CHECK(lost[0].text == "the printer stopped answering (nothing heard for 15 s between prints)");
  for (int t = 16700; t <= 30000; t += 100) s.on_tick(milliseconds(t));
  CHECK(s.take_events().empty());  // said once
  CHECK(s.state() == SessionState::idle);

  config.autoreport_temperature = true;  // M155: the firmware reports, nothing to ask
  MarlinSession quiet(config);
  quiet.on_tick(milliseconds(0));
  CHECK(quiet.take_output().empty());
}

TEST_CASE(
    "a listening session hears the handshake: firmware, enabled capabilities, and the ok that ends it") {
  MarlinSession s;
  s.on_receive("FIRMWARE_NAME:Marlin 2.1.2 (salient-sim)\nCap:EMERGENCY_PARSER:1\nCap:AUTOREPORT_TEMP:0\n",
               milliseconds(5));
  CHECK(s.oks_heard() == 0);
  s.on_receive("ok\n", milliseconds(6));
  CHECK(s.oks_heard() == 1);
  const auto events = s.take_events();
  REQUIRE(events.size() == 2);  // a capability that is off says nothing
  CHECK(events[0].kind == SessionEvent::Kind::firmware);
  CHECK(events[0].text.find("Marlin") != std::string::npos);
  CHECK(events[1].kind == SessionEvent::Kind::capability);
  CHECK(events[1].text == "EMERGENCY_PARSER");
}
