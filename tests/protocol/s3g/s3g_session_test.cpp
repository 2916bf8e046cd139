// S3gSession against a small scripted board (a 512-byte ring, `line`, pause toggle, faults per
// packet): what it sends, given what the board answers or loses.
#include "protocol/s3g/s3g_session.hpp"

#include <doctest/doctest.h>

#include <deque>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/s3g_codes.hpp"

using namespace salient::protocol::s3g;
using std::chrono::milliseconds;

namespace {

enum class Fault { none, drop_packet, drop_reply, garble_reply, deaf };

// The board side of the contract, reduced to what the host can observe.
struct Board {
  std::deque<std::string> ring;
  std::size_t ring_bytes = 512;
  std::uint32_t line = 0;
  std::uint8_t state = 0;
  std::vector<std::string> executed;
  Millis action_time{2};  // one action starts every action_time while not paused
  Millis next_start{0};
  Millis deaf_until{0};
  bool silent = false;
  std::optional<std::uint8_t> sticky;  // 8B: every packet from then on
  std::size_t received = 0;
  std::map<std::string, int> queued;  // times each action was taken into the ring
  // Per received packet: a fault, or a reply code the board answers instead of acting.
  std::function<Fault(const std::string&)> fault = [](const std::string&) { return Fault::none; };
  std::function<std::optional<std::uint8_t>(const std::string&)> code = [](const std::string&) {
    return std::optional<std::uint8_t>();
  };

  std::size_t used() const {
    std::size_t n = 0;
    for (const auto& a : ring) n += a.size();
    return n;
  }
  void advance(Millis now) {
    while (!ring.empty() && state != 3 && now >= next_start) {
      const std::string a = ring.front();
      ring.pop_front();
      executed.push_back(a);
      ++line;
      if (static_cast<std::uint8_t>(a[0]) == 153) state = 1;
      if (static_cast<std::uint8_t>(a[0]) == 154) state = 2;
      next_start += action_time;
    }
    if (ring.empty()) next_start = std::max(next_start, now);
  }
  void reset(Millis now) {
    ring.clear(), line = 0, state = 0;
    deaf_until = now + Millis(1000);
  }
  // The reply payload to a packet, or nullopt when none goes back.
  std::optional<std::string> answer(const std::string& p) {
    ++received;
    if (sticky) return std::string(1, static_cast<char>(*sticky));
    if (auto c = code(p)) {
      if (*c == 0x8B) sticky = c;
      return std::string(1, static_cast<char>(*c));
    }
    std::string r(1, '\x81');
    const auto id = static_cast<std::uint8_t>(p[0]);
    if (id >= 128) {
      if (used() + p.size() > ring_bytes) return std::string(1, '\x82');
      ring.push_back(p);
      ++queued[p];
      return r;
    }
    switch (id) {
      case 0:
        put_u16(r, 707);
        break;
      case 27:
        put_u16(r, 707), put_u16(r, 0), put_u8(r, 0x80), put_u8(r, 0), put_u16(r, 0);
        break;
      case 2:
        put_u32(r, static_cast<std::uint32_t>(ring_bytes - used()));
        break;
      case 24:
        put_u8(r, state), put_u8(r, 0), put_u8(r, 0), put_u32(r, line), put_u32(r, 0);
        break;
      case 10: {
        const auto c = static_cast<std::uint8_t>(p[2]);
        put_i16(r, c == 2 ? 205 : c == 32 ? 210 : c == 30 ? 100 : 110);
        break;
      }
      case 8:
        if (state == 1)
          state = 3;
        else if (state == 3)
          state = 1;
        break;
      case 7:
      case 22:
        ring.clear();
        break;
      default:
        return std::string(1, '\x85');
    }
    return r;
  }
};

// Runs the session against the board in simulated time.
struct Wire {
  Wire(S3gSession& session, Board& board) : s(session), b(board) {}
  S3gSession& s;
  Board& b;
  Millis t{0};
  std::vector<std::string> sent;
  std::string pending;  // written while the last packets were answered
  bool bytewise = false, garbage = false;

  void deliver(const std::string& bytes) {
    if (!bytewise) return s.on_receive(bytes, t);
    for (char c : bytes) s.on_receive(std::string(1, c), t);
  }
  // One turn: the host's packets answered, then time moves to the next thing due.
  void turn() {
    const std::string out = std::exchange(pending, {}) + s.take_output();
    PacketDecoder d;
    for (char c : out) {
      const auto r = d.feed(static_cast<std::uint8_t>(c));
      REQUIRE(r.error == PacketDecoder::Error::none);
      if (!r.payload) continue;
      sent.push_back(*r.payload);
      b.advance(t);
      if (b.silent || t < b.deaf_until) continue;
      const Fault f = b.fault(*r.payload);
      if (f == Fault::drop_packet || f == Fault::deaf) continue;
      const auto reply = b.answer(*r.payload);
      if (!reply || f == Fault::drop_reply) continue;
      std::string framed = frame(*reply);
      if (f == Fault::garble_reply) framed.back() = static_cast<char>(framed.back() ^ 0x5A);
      if (garbage) framed = std::string("\x13\x37", 2) + framed;
      t += Millis(1);
      deliver(framed);
    }
    pending = s.take_output();
    if (pending.empty() && out.empty()) {
      const Millis next = std::min(s.deadline(), t + Millis(10));
      t = std::max(next, t + Millis(1));
    } else {
      t += Millis(1);
    }
    b.advance(t);
    s.on_tick(t);
  }
  // Turns until `done` or `limit` of simulated time.
  template <class F>
  void until(F done, Millis limit = Millis(600000)) {
    const Millis end = t + limit;
    while (!done() && t < end) turn();
  }
  void finish(Millis limit = Millis(600000)) {
    until(
        [&] { return s.state() != SessionState::printing && s.state() != SessionState::paused && s.idle(); },
        limit);
  }
  std::size_t count_sent(const std::string& payload) const {
    return static_cast<std::size_t>(std::count(sent.begin(), sent.end(), payload));
  }
};

// A program of `n` commands; command i makes one or two actions (queue points and tool actions),
// each payload unique so a duplicate would show.
std::shared_ptr<X3gProgram> make_program(std::size_t n) {
  auto p = std::make_shared<X3gProgram>();
  for (std::size_t i = 0; i < n; ++i) {
    std::string a(1, static_cast<char>(155));
    for (int k = 0; k < 5; ++k) put_i32(a, static_cast<std::int32_t>(i * 10 + k));
    put_u32(a, 1000), put_u8(a, 0x18), put_f32(a, 1.0f), put_u16(a, 64);
    p->actions.push_back(a), p->source.push_back(i);
    if (i % 3 == 0) {
      std::string t = {static_cast<char>(136), 0, 3, 2};
      put_i16(t, static_cast<std::int16_t>(i));
      p->actions.push_back(t), p->source.push_back(i);
    }
  }
  p->commands = n;
  return p;
}

std::vector<SessionEvent> events_of(std::vector<SessionEvent>& all, S3gSession& s) {
  for (auto& e : s.take_events()) all.push_back(e);
  return all;
}

bool has_event(const std::vector<SessionEvent>& all, SessionEvent::Kind k) {
  return std::any_of(all.begin(), all.end(), [&](const SessionEvent& e) { return e.kind == k; });
}

}  // namespace

TEST_CASE("handshake: version with the host version, then advanced version: Sailfish 7.7") {
  S3gSession s;
  Board b;
  Wire w{s, b};
  s.handshake(Millis(0));
  w.until([&] { return s.handshake_done(); }, Millis(5000));
  REQUIRE(s.handshake_done());
  CHECK(s.firmware_name() == "Sailfish 7.7");
  CHECK(s.sailfish());
  REQUIRE(w.sent.size() >= 2);
  CHECK(w.sent[0] == std::string("\x00\x64\x00", 3));
  CHECK(w.sent[1] == std::string("\x1B\x64\x00", 3));
  std::vector<SessionEvent> ev;
  events_of(ev, s);
  CHECK(has_event(ev, SessionEvent::Kind::firmware));
}

TEST_CASE("a firmware without query 27 is MakerBot's own, not an error") {
  S3gSession s;
  Board b;
  b.code = [](const std::string& p) { return p[0] == 27 ? std::optional<std::uint8_t>(0x85) : std::nullopt; };
  Wire w{s, b};
  s.handshake(Millis(0));
  w.until([&] { return s.handshake_done(); }, Millis(5000));
  CHECK(s.firmware_name() == "MakerBot firmware 7.7");
  CHECK_FALSE(s.sailfish());
}

TEST_CASE("a clean print: every action once, in order, progress in commands, finished when all started") {
  S3gSession s;
  Board b;
  Wire w{s, b};
  auto p = make_program(200);
  s.begin(p, Millis(0));
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.state() != SessionState::printing;
  });
  CHECK(s.state() == SessionState::finished);
  CHECK(b.executed == p->actions);
  CHECK(s.commands_done() == 200);
  CHECK(s.packets_resent() == 0);
  std::size_t last = 0;
  for (const auto& e : ev)
    if (e.kind == SessionEvent::Kind::acknowledged) {
      CHECK(e.done > last);
      last = e.done;
    }
  CHECK(last == 200);
  CHECK(has_event(ev, SessionEvent::Kind::temperatures) == (w.t > Millis(2000)));
  // Nothing but known packets went: the handshake-free begin starts with the baseline (24, 2, 24).
  REQUIRE(w.sent.size() >= 3);
  CHECK(w.sent[0] == std::string(1, '\x18'));
  CHECK(w.sent[1] == std::string(1, '\x02'));
  CHECK(w.sent[2] == std::string(1, '\x18'));
}

TEST_CASE("temperatures are polled while printing, hotend and bed in pairs") {
  S3gSession s;
  Board b;
  b.action_time = Millis(40);
  Wire w{s, b};
  auto p = make_program(100);
  s.begin(p, Millis(0));
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.state() != SessionState::printing;
  });
  CHECK(s.state() == SessionState::finished);
  CHECK(b.executed == p->actions);
  bool hotend = false, bed = false;
  for (const auto& e : ev) {
    if (e.kind != SessionEvent::Kind::temperatures) continue;
    if (e.temperatures.hotend)
      hotend = *e.temperatures.hotend == 205 && e.temperatures.hotend_target == 210.0;
    if (e.temperatures.bed) bed = *e.temperatures.bed == 100 && e.temperatures.bed_target == 110.0;
  }
  CHECK(hotend);
  CHECK(bed);
}

TEST_CASE("resume: the first commands are skipped and the prelude goes first") {
  S3gSession s;
  Board b;
  Wire w{s, b};
  auto p = make_program(30);
  const std::string prelude = std::string{static_cast<char>(136), 0, 3, 2, '\xC8', 0};
  s.begin(p, Millis(0), 10, {prelude});
  w.finish();
  CHECK(s.state() == SessionState::finished);
  std::vector<std::string> want = {prelude};
  want.insert(want.end(), p->actions.begin() + static_cast<long>(p->first_action_of(10)), p->actions.end());
  CHECK(b.executed == want);
  CHECK(s.commands_done() == 30);
}

TEST_CASE("a bad prelude action is refused before anything goes") {
  S3gSession s;
  CHECK_THROWS_AS(s.begin(make_program(2), Millis(0), 0, {std::string(1, '\x02')}), std::invalid_argument);
  CHECK_THROWS_AS(s.begin(make_program(2), Millis(0), 0, {std::string(33, '\x9B')}), std::invalid_argument);
}

TEST_CASE(
    "resend codes 80 83 88 8C (and 84 for a packet that was not too big): the same packet again, once run") {
  for (std::uint8_t code : {0x80, 0x83, 0x88, 0x8C, 0x84}) {
    CAPTURE(int(code));
    S3gSession s;
    Board b;
    auto p = make_program(20);
    const std::string victim = p->actions[7];
    int left = 2;
    b.code = [&](const std::string& pk) {
      return pk == victim && left-- > 0 ? std::optional<std::uint8_t>(code) : std::nullopt;
    };
    Wire w{s, b};
    s.begin(p, Millis(0));
    w.finish();
    CHECK(s.state() == SessionState::finished);
    CHECK(b.executed == p->actions);
    CHECK(s.packets_resent() == 2);
    CHECK(w.count_sent(victim) == 3);
  }
}

TEST_CASE("more than five resends of one packet fail the print, resumable from what was confirmed") {
  S3gSession s;
  Board b;
  auto p = make_program(20);
  const std::string victim = p->actions[7];
  b.code = [&](const std::string& pk) {
    return pk == victim ? std::optional<std::uint8_t>(0x83) : std::nullopt;
  };
  Wire w{s, b};
  s.begin(p, Millis(0));
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.state() != SessionState::printing;
  });
  CHECK(s.state() == SessionState::failed);
  CHECK(w.count_sent(victim) == 6);
  CHECK(s.commands_done() == p->command_of(7));
  CHECK(has_event(ev, SessionEvent::Kind::failed));
}

TEST_CASE("82 buffer full: poll free space until the action fits, then send it: a slow board and a storm") {
  S3gSession s;
  Board b;
  b.action_time = Millis(30);  // the ring fills: real 82s
  auto p = make_program(80);
  int storm = 0;
  b.code = [&](const std::string& pk) {  // and refusals of actions that fit, in bursts
    if (static_cast<std::uint8_t>(pk[0]) < 128) return std::optional<std::uint8_t>();
    if (++storm % 17 < 6) return std::optional<std::uint8_t>(0x82);
    return std::optional<std::uint8_t>();
  };
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.finish();
  CHECK(s.state() == SessionState::finished);
  CHECK(b.executed == p->actions);
  CHECK(w.count_sent(std::string(1, '\x02')) > 10);  // it polled free space
  CHECK(s.packets_resent() == 0);                    // 82 is flow control, not a resend
}

TEST_CASE("stop codes end the print with their reason: 89 cancelled, 8A and 8B failed") {
  for (std::uint8_t code : {0x89, 0x8A, 0x8B}) {
    CAPTURE(int(code));
    S3gSession s;
    Board b;
    auto p = make_program(20);
    const std::string victim = p->actions[5];
    b.code = [&](const std::string& pk) {
      return pk == victim ? std::optional<std::uint8_t>(code) : std::nullopt;
    };
    Wire w{s, b};
    s.begin(p, Millis(0));
    std::vector<SessionEvent> ev;
    w.finish();
    events_of(ev, s);
    CHECK(s.state() == (code == 0x89 ? SessionState::cancelled : SessionState::failed));
    REQUIRE(!ev.empty());
    CHECK(ev.back().text == std::string(reply_name(code)));
    CHECK(b.executed.size() <= 5);
  }
}

TEST_CASE("8B on a query (heater shutdown) also stops the print") {
  S3gSession s;
  Board b;
  b.action_time = Millis(100);
  b.code = [&](const std::string& pk) {
    return pk[0] == 10 ? std::optional<std::uint8_t>(0x8B) : std::optional<std::uint8_t>();
  };
  Wire w{s, b};
  s.begin(make_program(200), Millis(0));
  w.finish();
  CHECK(s.state() == SessionState::failed);
}

TEST_CASE("fatal codes 85 87 fail the print") {
  for (std::uint8_t code : {0x85, 0x87}) {
    CAPTURE(int(code));
    S3gSession s;
    Board b;
    auto p = make_program(20);
    const std::string victim = p->actions[3];
    b.code = [&](const std::string& pk) {
      return pk == victim ? std::optional<std::uint8_t>(code) : std::nullopt;
    };
    Wire w{s, b};
    s.begin(p, Millis(0));
    std::vector<SessionEvent> ev;
    w.finish();
    events_of(ev, s);
    CHECK(s.state() == SessionState::failed);
    CHECK(ev.back().text.find(std::string(reply_name(code))) != std::string::npos);
  }
}

TEST_CASE("replies split byte by byte and behind garbage are read the same") {
  S3gSession s;
  Board b;
  Wire w{s, b};
  w.bytewise = true, w.garbage = true;
  auto p = make_program(40);
  s.begin(p, Millis(0));
  w.finish();
  CHECK(s.state() == SessionState::finished);
  CHECK(b.executed == p->actions);
  CHECK(s.timeouts() == 0);
}

TEST_CASE("a lost reply to a queued action: resolved from the ring, never sent twice") {
  for (Fault f : {Fault::drop_reply, Fault::garble_reply}) {
    for (Millis action_time : {Millis(2), Millis(200), Millis(5000)}) {
      CAPTURE(int(f));
      CAPTURE(action_time.count());
      S3gSession s;
      Board b;
      b.action_time = action_time;  // started already, still queued behind others, or the only one queued
      auto p = make_program(30);
      std::set<std::size_t> victims = {4, 11, 12, 25};
      std::size_t seen = 0;
      std::map<std::string, int> times;
      b.fault = [&](const std::string& pk) {
        if (static_cast<std::uint8_t>(pk[0]) < 128) return Fault::none;
        if (times[pk]++ > 0) return Fault::none;
        return victims.count(seen++) ? f : Fault::none;
      };
      Wire w{s, b};
      s.begin(p, Millis(0));
      w.finish(Millis(3600000));
      CHECK(s.state() == SessionState::finished);
      CHECK(b.executed == p->actions);
      // Each lost reply was resolved; "not queued" only where the board had refused it (82).
      CHECK(s.doubts_resolved() == 4);
      if (action_time < Millis(100)) CHECK(s.doubts_queued() == 4);
      for (const auto& a : p->actions) CHECK(b.queued[a] == 1);
    }
  }
}

TEST_CASE("a lost packet (the board never saw it): resolved as not queued, sent again once") {
  S3gSession s;
  Board b;
  b.action_time = Millis(50);
  auto p = make_program(30);
  std::map<std::string, int> times;
  std::size_t seen = 0;
  b.fault = [&](const std::string& pk) {
    if (static_cast<std::uint8_t>(pk[0]) < 128 || times[pk]++ > 0) return Fault::none;
    ++seen;
    return seen == 3 || seen == 20 ? Fault::drop_packet : Fault::none;
  };
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.finish();
  CHECK(s.state() == SessionState::finished);
  CHECK(b.executed == p->actions);
  CHECK(s.doubts_not_queued() == 2);
  CHECK(s.doubts_queued() == 0);
  CHECK(s.timeouts() >= 2);
}

TEST_CASE("a board that stops answering fails the print after the silence limit, resumable") {
  SessionConfig c;
  c.silence_limit = Millis(5000);
  S3gSession s(c);
  Board b;
  auto p = make_program(50);
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return s.commands_done() >= 20; });
  const Millis stopped = w.t;
  b.silent = true;
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.state() != SessionState::printing;
  });
  CHECK(s.state() == SessionState::failed);
  CHECK(w.t - stopped >= Millis(5000));
  CHECK(w.t - stopped < Millis(7000));
  CHECK(ev.back().text.find("stopped answering") != std::string::npos);
  CHECK(s.commands_done() >= 20);
  CHECK(s.commands_done() < 50);
}

TEST_CASE("pause: a toggle confirmed by build stats, nothing sent while paused, resume toggles back") {
  S3gSession s;
  Board b;
  b.action_time = Millis(20);
  auto p = make_program(100);
  p->actions.insert(p->actions.begin(), std::string{static_cast<char>(153), 0, 0, 0, 0, 'x', 0});
  p->source.insert(p->source.begin(), 0);
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return s.commands_done() >= 30; });
  s.pause();
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.pause_confirmed();
  });
  CHECK(has_event(ev, SessionEvent::Kind::paused));
  CHECK(b.state == 3);
  CHECK(w.count_sent(std::string(1, '\x08')) == 1);
  const std::size_t sent_at_pause = w.sent.size();
  const std::size_t done = s.commands_done();
  w.until([] { return false; }, Millis(5000));
  for (std::size_t i = sent_at_pause; i < w.sent.size(); ++i)
    CHECK(static_cast<std::uint8_t>(w.sent[i][0]) < 128);
  CHECK(s.commands_done() == done);
  s.resume(w.t);
  w.finish();
  events_of(ev, s);
  CHECK(has_event(ev, SessionEvent::Kind::resumed));
  CHECK(w.count_sent(std::string(1, '\x08')) == 2);
  CHECK(s.state() == SessionState::finished);
  CHECK(b.executed == p->actions);
}

TEST_CASE("a lost pause toggle is checked with build stats before toggling again") {
  S3gSession s;
  Board b;
  b.action_time = Millis(20);
  auto p = make_program(100);
  p->actions.insert(p->actions.begin(), std::string{static_cast<char>(153), 0, 0, 0, 0, 'x', 0});
  p->source.insert(p->source.begin(), 0);
  int toggles = 0;
  b.fault = [&](const std::string& pk) {
    if (pk[0] != 8) return Fault::none;
    ++toggles;
    return toggles == 1 ? Fault::drop_packet : toggles == 2 ? Fault::drop_reply : Fault::none;
  };
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return s.commands_done() >= 30; });
  s.pause();
  w.until([&] { return s.pause_confirmed(); }, Millis(20000));
  CHECK(s.pause_confirmed());
  CHECK(b.state == 3);
  CHECK(toggles == 2);  // the second toggle took (its reply lost): no third that would undo it
  w.until([] { return false; }, Millis(5000));
  CHECK(b.state == 3);
  CHECK(toggles == 2);
}

TEST_CASE("cancel: abort (7) clears the ring, then heaters off and motors off") {
  S3gSession s;
  Board b;
  b.action_time = Millis(50);
  auto p = make_program(100);
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return s.commands_done() >= 20; });
  const std::size_t before = w.sent.size();
  s.cancel(S3gSession::cancel_cleanup(), w.t);
  std::vector<SessionEvent> ev;
  w.finish();
  events_of(ev, s);
  CHECK(s.state() == SessionState::cancelled);
  CHECK(s.idle());
  CHECK(has_event(ev, SessionEvent::Kind::cancelled));
  std::vector<std::string> after;
  for (std::size_t i = before; i < w.sent.size(); ++i)
    if (w.sent[i][0] != 10 && w.sent[i][0] != 24) after.push_back(w.sent[i]);
  REQUIRE(after.size() >= 4);
  CHECK(after[after.size() - 4] == std::string(1, '\x07'));
  CHECK(after[after.size() - 3] == std::string("\x88\x00\x03\x02\x00\x00", 6));
  CHECK(after[after.size() - 2] == std::string("\x88\x00\x1F\x02\x00\x00", 6));
  CHECK(after[after.size() - 1] == std::string("\x89\x1F", 2));
  CHECK(b.executed.size() < p->actions.size());
  b.advance(w.t + Millis(1000));  // the cleanup runs on the board after it was acked
  CHECK(b.executed.back() == std::string("\x89\x1F", 2));
}

TEST_CASE("emergency stop: extended stop (22, halt and clear) first, then the heaters") {
  S3gSession s;
  Board b;
  b.action_time = Millis(50);
  Wire w{s, b};
  s.begin(make_program(100), Millis(0));
  w.until([&] { return s.commands_done() >= 10; });
  w.turn();
  const std::size_t before = w.sent.size();
  s.emergency_stop(S3gSession::heaters_off(), w.t);
  w.finish();
  CHECK(s.state() == SessionState::cancelled);
  std::vector<std::string> after(w.sent.begin() + static_cast<long>(before), w.sent.end());
  REQUIRE(after.size() >= 3);
  const auto stop = std::find(after.begin(), after.end(), std::string("\x16\x03", 2));
  REQUIRE(stop != after.end());
  CHECK(*(stop + 1) == std::string("\x88\x00\x03\x02\x00\x00", 6));
  CHECK(*(stop + 2) == std::string("\x88\x00\x1F\x02\x00\x00", 6));
}

TEST_CASE("reset mid-print: detected, reported, resumable from the commands whose actions all started") {
  S3gSession s;
  Board b;
  b.action_time = Millis(30);  // the ring holds actions acked but not started when it resets
  auto p = make_program(120);
  p->actions.insert(p->actions.begin(), std::string{static_cast<char>(153), 0, 0, 0, 0, 'x', 0});
  p->source.insert(p->source.begin(), 0);
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return b.executed.size() >= 60; });
  b.reset(w.t);
  const std::size_t ran = b.executed.size();
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.state() != SessionState::printing;
  });
  CHECK(s.state() == SessionState::failed);
  CHECK(has_event(ev, SessionEvent::Kind::reset));
  CHECK(ev.back().text == "the printer reset");
  const std::size_t resume = s.commands_done();
  // Every action of the commands reported done had run; none is claimed that had not started.
  CHECK(p->first_action_of(resume) <= ran);
  // ... and it lags by at most the actions of a build stats interval (1 s, 30 ms each: 34).
  CHECK(p->first_action_of(resume) + 40 > ran);
  // Resuming from there prints the rest exactly once more.
  S3gSession again;
  Board b2 = Board{};
  Wire w2{again, b2};
  again.begin(p, Millis(0), resume);
  w2.finish();
  CHECK(again.state() == SessionState::finished);
  std::vector<std::string> rest(p->actions.begin() + static_cast<long>(p->first_action_of(resume)),
                                p->actions.end());
  CHECK(b2.executed == rest);
}

TEST_CASE("a reset while nothing had started yet is still detected: the ring lost what it held") {
  S3gSession s;
  Board b;
  b.action_time = Millis(100000);  // the first action blocks (a heating wait): the rest stays queued
  auto p = make_program(40);
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return b.used() > 300; });
  b.reset(w.t);
  b.action_time = Millis(100000);
  std::vector<SessionEvent> ev;
  w.until([&] {
    events_of(ev, s);
    return s.state() != SessionState::printing;
  });
  CHECK(s.state() == SessionState::failed);
  CHECK(has_event(ev, SessionEvent::Kind::reset));
  CHECK(s.commands_done() <= 1);
}

TEST_CASE("listening between prints: temperatures polled, silence reported once") {
  SessionConfig c;
  c.idle_poll = Millis(1000), c.idle_silence_limit = Millis(4000);
  S3gSession s(c);
  Board b;
  Wire w{s, b};
  s.on_tick(Millis(0));
  std::vector<SessionEvent> ev;
  w.until([] { return false; }, Millis(3000));
  events_of(ev, s);
  CHECK(has_event(ev, SessionEvent::Kind::temperatures));
  CHECK_FALSE(has_event(ev, SessionEvent::Kind::timeout));
  b.silent = true;
  w.until([] { return false; }, Millis(10000));
  ev.clear();
  events_of(ev, s);
  CHECK(std::count_if(ev.begin(), ev.end(),
                      [](const SessionEvent& e) { return e.kind == SessionEvent::Kind::timeout; }) == 1);
}

TEST_CASE("random faults both ways: every action runs exactly once, in order") {
  for (std::uint32_t seed : {1u, 2u, 3u, 4u, 5u}) {
    CAPTURE(seed);
    S3gSession s;
    Board b;
    b.action_time = Millis(1);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    b.fault = [&](const std::string&) {
      const double r = u(rng);
      if (r < 0.02) return Fault::garble_reply;
      if (r < 0.03) return Fault::drop_reply;
      if (r < 0.04) return Fault::drop_packet;
      return Fault::none;
    };
    b.code = [&](const std::string& p) {
      const double r = u(rng);
      if (r < 0.02) return std::optional<std::uint8_t>(0x83);  // corrupted on the way in
      if (r < 0.03) return std::optional<std::uint8_t>(0x8C);
      if (static_cast<std::uint8_t>(p[0]) >= 128 && r < 0.06) return std::optional<std::uint8_t>(0x82);
      return std::optional<std::uint8_t>();
    };
    auto p = make_program(1500);
    Wire w{s, b};
    s.begin(p, Millis(0));
    w.finish(Millis(36000000));
    CHECK(s.state() == SessionState::finished);
    CHECK(b.executed == p->actions);
    CHECK(s.doubts_resolved() > 10);
    CHECK(s.packets_resent() > 10);
  }
}

TEST_CASE("interrupt behind a full ring: the heaters-off actions wait for room, what was acked still runs") {
  S3gSession s;
  Board b;
  b.action_time = Millis(100);
  auto p = make_program(200);
  Wire w{s, b};
  s.begin(p, Millis(0));
  w.until([&] { return s.commands_done() >= 40 && b.used() > 480; });
  s.cancel(S3gSession::heaters_off(), w.t, false);
  std::vector<SessionEvent> ev;
  w.finish();
  events_of(ev, s);
  CHECK(s.state() == SessionState::cancelled);
  CHECK(ev.back().kind == SessionEvent::Kind::cancelled);
  CHECK(ev.back().text == "cancelled");
  b.advance(w.t + Millis(100000));
  // Every action acked ran, then the heaters went off: the print resumes from commands_done().
  REQUIRE(b.executed.size() >= 2);
  CHECK(b.executed[b.executed.size() - 2] == std::string("\x88\x00\x03\x02\x00\x00", 6));
  CHECK(b.executed.back() == std::string("\x88\x00\x1F\x02\x00\x00", 6));
  const std::size_t ran = b.executed.size() - 2;
  CHECK(std::vector<std::string>(b.executed.begin(), b.executed.begin() + static_cast<long>(ran)) ==
        std::vector<std::string>(p->actions.begin(), p->actions.begin() + static_cast<long>(ran)));
  CHECK(p->first_action_of(s.commands_done()) <= ran);
  CHECK(s.commands_done() == p->command_of(ran));
}

TEST_CASE(
    "a line that answers garbage (random bytes, random frames) fails the print, never hangs or crashes") {
  for (std::uint32_t seed : {11u, 12u, 13u}) {
    for (bool framed : {false, true}) {
      CAPTURE(seed);
      CAPTURE(framed);
      S3gSession s;
      std::mt19937 rng(seed);
      auto p = make_program(50);
      s.begin(p, Millis(0));
      Millis t{0};
      for (int turn = 0; turn < 200000 && s.state() == SessionState::printing; ++turn) {
        const std::string out = s.take_output();
        if (!out.empty()) {
          std::string junk(rng() % 40, '\0');
          for (char& c : junk) c = static_cast<char>(rng());
          if (framed) junk = frame(junk.empty() ? std::string(1, '\x81') : junk.substr(0, 32));
          s.on_receive(junk, t);
        }
        t += Millis(1 + rng() % 20);
        s.on_tick(t);
      }
      CHECK(s.state() != SessionState::printing);
      CHECK(t < Millis(3600000));
    }
  }
}

// Issue 32: a host stopped for longer than the silence limit (SIGSTOP, a suspended VM) polled
// nothing meanwhile; on waking it must not call its idle board gone.
TEST_CASE("listening: a host away longer than the silence limit does not call its board gone") {
  SessionConfig c;
  c.idle_poll = Millis(1000), c.idle_silence_limit = Millis(4000);
  S3gSession s(c);
  Board b;
  Wire w{s, b};
  s.on_tick(Millis(0));
  w.until([] { return false; }, Millis(3000));
  std::vector<SessionEvent> ev;
  events_of(ev, s);
  w.t += Millis(20000);  // the host was stopped; it ticks before it reads what came meanwhile
  s.on_tick(w.t);
  events_of(ev, s);
  CHECK_FALSE(has_event(ev, SessionEvent::Kind::timeout));
  w.until([] { return false; }, Millis(3000));
  events_of(ev, s);
  CHECK_FALSE(has_event(ev, SessionEvent::Kind::timeout));
  b.silent = true;  // and a board that stops answering is still found out
  w.until([] { return false; }, Millis(6000));
  events_of(ev, s);
  CHECK(has_event(ev, SessionEvent::Kind::timeout));
}
