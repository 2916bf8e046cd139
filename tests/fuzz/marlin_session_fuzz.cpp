// Fuzz target for the Marlin host session: arbitrary bytes from the "firmware", cut into reads,
// with time passing. It must not crash, every line it sends must frame correctly, it must never
// count more commands done than it was given, and it must never send a line number again unless
// a Resend request for that line or an earlier one came in since. A second session that began no
// print hears the same bytes, as in a handshake or between prints: it may only poll (unnumbered
// M105) and report firmware, capabilities, temperatures, errors, restarts and, once, silence.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/marlin/marlin_session.hpp"

using namespace salient::protocol::marlin;

namespace {

struct Checker {
  std::map<long long, bool> may_send_again;  // line number → a resend request covers it

  void check(MarlinSession& s) {
    for (const SessionEvent& e : s.take_events())
      if (e.kind == SessionEvent::Kind::resend)
        for (auto it = may_send_again.lower_bound(e.line); it != may_send_again.end(); ++it)
          it->second = true;
    std::istringstream out(s.take_output());
    for (std::string line; std::getline(out, line);) {
      if (line == "M112") continue;
      FrameError error;
      const FramedLine f = parse_frame(line, error);
      if (error != FrameError::none || !f.number) std::abort();
      const long long n = static_cast<long long>(*f.number);
      auto [it, first] = may_send_again.try_emplace(n, false);
      if (!first && !it->second) std::abort();  // sent twice without a resend request
      it->second = false;
    }
    if (s.commands_done() > s.commands_total()) std::abort();
  }
};

void check_idle(MarlinSession& s, int& timeouts) {
  using K = SessionEvent::Kind;
  for (const SessionEvent& e : s.take_events()) {
    if (e.kind != K::temperatures && e.kind != K::error && e.kind != K::reset && e.kind != K::timeout)
      std::abort();
    if (e.kind == K::timeout && ++timeouts > 1) std::abort();
  }
  std::istringstream out(s.take_output());
  for (std::string line; std::getline(out, line);)
    if (line != "M105") std::abort();
  if (s.state() != SessionState::idle || s.commands_total() != 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SessionConfig config;
  config.reply_timeout = std::chrono::milliseconds(50);
  config.resend_ok_wait = std::chrono::milliseconds(20);
  config.idle_poll = std::chrono::milliseconds(30);
  config.idle_silence_limit = std::chrono::milliseconds(200);
  MarlinSession s(config), idle(config);
  Checker checker;
  int idle_timeouts = 0;
  s.begin({"G28", "G1 X10 Y10 F3000", "M104 S200", "G1 X20 E1", "M105", "G1 X1", "G1 X2", "G1 X3"},
          Millis(0));
  checker.check(s);
  std::size_t at = 0;
  long long now = 0;
  while (at < size) {
    const std::size_t chunk = 1 + data[at] % 32;
    std::string_view bytes(reinterpret_cast<const char*>(data) + at + 1, std::min(chunk, size - at - 1));
    at += 1 + bytes.size();
    now += data[at - 1] % 100;
    // One reply line per call, so that a Resend's event comes before the lines it makes us send.
    while (!bytes.empty()) {
      const std::size_t nl = bytes.find('\n');
      const std::size_t take = nl == std::string_view::npos ? bytes.size() : nl + 1;
      s.on_receive(bytes.substr(0, take), Millis(now));
      idle.on_receive(bytes.substr(0, take), Millis(now));
      bytes.remove_prefix(take);
      checker.check(s);
      check_idle(idle, idle_timeouts);
    }
    s.on_tick(Millis(now));
    idle.on_tick(Millis(now));
    checker.check(s);
    check_idle(idle, idle_timeouts);
  }
  return 0;
}
