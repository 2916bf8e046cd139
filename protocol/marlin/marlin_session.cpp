// MarlinSession. Flow control: one line in flight (ping-pong) until the firmware shows
// ADVANCED_OK ("ok N P B"); then up to B lines, never more bytes than its receive buffer.
//
// Which line an ok acknowledges: with ADVANCED_OK the ok names it (N), so a lost ok is made up by
// the next one; "ok T:…" is M105's own reply and settles everything up to the M105 in flight;
// a plain ok in ping-pong acknowledges the oldest line, unless it answers a Resend.
//
// Resends: Marlin discards its receive buffer after a bad line and answers every line that then
// arrives with "Resend: N" (+ "ok"). We rewind once to N, keep the lines before N in flight (they
// were taken), treat the requests drawn by the lines that were behind N as repeats (a checksum
// error is never a repeat: only line N itself can fail its checksum, since the line number is
// checked first), and give up after max_resends_of_one_line requests for the same line.
// A silence with lines in flight sends an M105 poke and holds further lines until it is answered;
// the wait adapts to the reply times seen (RFC 6298), pokes back off up to poke_interval, and a
// printer that says nothing at all for silence_limit after a poke has stopped: the print fails.
#include "protocol/marlin/marlin_session.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <optional>
#include <utility>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol::marlin {
namespace {

bool is_m105(const std::string& command) {
  return command == "M105" || command.rfind("M105 ", 0) == 0;
}

std::string_view code_of(std::string_view command) {
  return command.substr(0, command.find(' '));
}

bool waits_for_heat(std::string_view command) {
  const std::string_view c = code_of(command);
  return c == "M109" || c == "M190" || c == "M191";
}

// Commands whose ok comes when the work is done, which may take seconds to minutes.
bool is_slow(std::string_view command) {
  static constexpr std::string_view slow[] = {"G28",  "G29",  "G30",  "G33",  "G34",  "G35",  "G76",
                                              "G425", "M48",  "M109", "M190", "M191", "M303", "M400",
                                              "G4",   "M600", "M0",   "M1",   "M226", "M116", "M1001"};
  const std::string_view c = code_of(command);
  return std::find(std::begin(slow), std::end(slow), c) != std::end(slow);
}

}  // namespace

MarlinSession::MarlinSession(SessionConfig config)
    : config_(config), expect_ok_after_resend_(config.ok_after_resend != SessionConfig::OkAfterResend::no) {}

void MarlinSession::begin(const std::vector<std::string>& commands, Millis now, std::size_t resume_from,
                          const std::vector<std::string>& prelude) {
  begin(std::make_shared<const Program>(Program::from_lines(commands)), now, resume_from, prelude);
}

void MarlinSession::begin(std::shared_ptr<const Program> program, Millis now, std::size_t resume_from,
                          const std::vector<std::string>& prelude) {
  queue_.clear();
  sent_.clear();
  in_flight_.clear();
  bytes_in_flight_ = 0;
  next_line_ = 0;
  program_ = program ? std::move(program) : std::make_shared<const Program>();
  queue_.emplace_back("M110 N0", false);  // the firmware now expects line 1 next
  for (const std::string& line : prelude) {
    std::string command = strip_comment(line);
    if (!command.empty()) queue_.emplace_back(std::move(command), false);
  }
  std::string refused;
  for (const Program::Command& c : program_->commands())
    if (std::string why = unsendable(c.text); !why.empty()) {
      refused = "line " + std::to_string(c.line) + " cannot be sent: " + why;
      break;
    }
  total_ = program_->size();
  done_ = next_command_ = std::min(resume_from, total_);
  state_ = SessionState::printing;
  last_heard_ = now;
  if (!refused.empty()) return fail(refused);  // checked before anything goes: it would stall mid-print
  pump(now);
}

void MarlinSession::pause() {
  if (state_ == SessionState::printing) state_ = SessionState::paused;
}

void MarlinSession::resume(Millis now) {
  if (state_ != SessionState::paused) return;
  state_ = SessionState::printing;
  pump(now);
}

void MarlinSession::send_now(const std::vector<std::string>& lines, Millis now) {
  if (state_ != SessionState::printing && state_ != SessionState::paused) return;
  for (const std::string& line : lines)
    if (std::string command = strip_comment(line); !command.empty()) console_.push_back(std::move(command));
  pump(now);
}

void MarlinSession::cancel(const std::vector<std::string>& cleanup, Millis now) {
  if (state_ != SessionState::printing && state_ != SessionState::paused) return;
  // Console lines asked for before the cancel still go, ahead of the cleanup, as OctoPrint's
  // command queue sends them: they were answered 204, and a heater set by one is then turned off.
  std::deque<std::string> console = std::exchange(console_, {});
  drop_queue();
  for (std::string& line : console) queue_.emplace_back(std::move(line), false);
  for (const std::string& line : cleanup) {
    std::string command = strip_comment(line);
    if (!command.empty()) queue_.emplace_back(std::move(command), false);
  }
  state_ = SessionState::cancelled;
  // A heating wait in flight would hold the cleanup (heaters off!) until the target is reached.
  const bool heating =
      std::any_of(in_flight_.begin(), in_flight_.end(), [](const InFlight& f) { return f.waits_for_heat; });
  if (heating && config_.emergency_parser) {
    break_heating_wait(now);
  } else if (heating) {
    output_ += "M112\n";  // no other way to stop it: the firmware halts, heaters off
    halted_ = true;
    fail(
        "cancelled during a heating wait: M112 sent, as the firmware has no EMERGENCY_PARSER to break it; "
        "reconnect to reset the printer");
    return;
  }
  last_heard_ = std::max(last_heard_, now);  // the cleanup's silence limit counts from the cancel
  pump(now);
}

// Marlin's emergency parser ends the wait under way when M108 arrives (and queues the line too,
// which is answered with an ok: so it goes numbered, and the oks stay in step). A wait that had
// not begun yet (M109 queued behind M190) is not ended by it: M108 goes again every 500 ms while a
// heating wait is in flight.
void MarlinSession::break_heating_wait(Millis now) {
  send_numbered("M108", false, now);
  next_m108_ = now + Millis(500);
}

void MarlinSession::emergency_stop() {
  output_ += "M112\n";
  drop_queue();
  state_ = SessionState::failed;
  events_.push_back({SessionEvent::Kind::failed, 0, "emergency stop", {}});
}

void MarlinSession::send_numbered(const std::string& command, bool counts, Millis now) {
  const long long line = next_line_++;
  const std::string framed = frame(static_cast<std::uint64_t>(line), command) + "\n";
  output_ += framed;
  sent_[line] = {command, counts};
  while (sent_.size() > 256) sent_.erase(sent_.begin());  // Marlin only asks for recent lines
  const bool was_empty = in_flight_.empty();
  if (line >= resent_below_ &&
      !(is_m105(command) && !counts)) {  // the first time it goes: the machine's state moves
    recent_moves_.push_back(motion_.duration_of(command));
    if (recent_moves_.size() > kPlannerDepth) recent_moves_.pop_front();
  }
  in_flight_.push_back({line, framed.size(), counts, is_m105(command), is_slow(command),
                        waits_for_heat(command), line < resent_below_, now});
  bytes_in_flight_ += framed.size();
  if (was_empty && !synchronising_) reply_deadline_ = now + timeout_for_front();
}

// How long a command keeps the machine busy at least: a move's length at its feed rate, with the
// time to accelerate (at a modest 500 mm/s²) for short ones. Modal state as Marlin keeps it.
Millis MarlinSession::Motion::duration_of(std::string_view c) {
  const std::string_view code = code_of(c);
  if (code == "G90")
    relative = false;
  else if (code == "G91")
    relative = true;
  else if (code == "G92") {
    for (int i = 0; i < 4; ++i)
      if (auto v = word_value(c, "XYZE"[i])) pos[i] = *v;
  }
  if (code != "G0" && code != "G1" && code != "G2" && code != "G3") return Millis(0);
  if (auto f = word_value(c, 'F'); f && *f > 0) feed = *f / 60;
  double d2 = 0, e = 0;
  for (int i = 0; i < 4; ++i) {
    const auto v = word_value(c, "XYZE"[i]);
    if (!v) continue;
    const double to = relative ? pos[i] + *v : *v;
    if (i < 3)
      d2 += (to - pos[i]) * (to - pos[i]);
    else
      e = std::fabs(to - pos[i]);
    pos[i] = to;
  }
  double d = d2 > 0 ? std::sqrt(d2) : e;
  if (code == "G2" || code == "G3")
    d *= 1.6;  // an arc is longer than its chord (up to π/2 for a half circle)
  const double seconds = std::max(d / feed, 2 * std::sqrt(d / 500.0));
  return Millis(static_cast<long long>(std::ceil(seconds * 1000)));
}

Millis MarlinSession::timeout_for_front() const {
  if (in_flight_.empty()) return Millis::max();
  if (in_flight_.front().slow) return config_.reply_timeout;
  // RFC 6298 §2: RTO = SRTT + max(G, 4·RTTVAR); before the first sample, the ceiling, so that
  // a printer slow from its first line is not poked while it is being learned.
  if (!have_rtt_) return config_.reply_timeout;
  const double rto = srtt_ms_ + std::max(10.0, 4 * rttvar_ms_);
  // With the planner full, an ok waits for the oldest queued move to end: the longest of the
  // moves sent lately is added, so that a long travel is not taken for a lost ok.
  const Millis busy =
      recent_moves_.empty() ? Millis(0) : *std::max_element(recent_moves_.begin(), recent_moves_.end());
  const Millis floor = std::min(config_.min_reply_timeout + busy, config_.reply_timeout);
  return std::clamp(Millis(static_cast<long long>(rto)) + busy, floor, config_.reply_timeout);
}

void MarlinSession::sample_reply_time(Millis sample) {
  const double r = static_cast<double>(sample.count());
  if (!have_rtt_) {
    srtt_ms_ = r, rttvar_ms_ = r / 2, have_rtt_ = true;
    return;
  }
  rttvar_ms_ = 0.75 * rttvar_ms_ + 0.25 * std::abs(srtt_ms_ - r);
  srtt_ms_ = 0.875 * srtt_ms_ + 0.125 * r;
}

void MarlinSession::pump(Millis now) {
  // Paused, only console lines go, and only when no host line (a resend) is due before them.
  const bool paused = state_ == SessionState::paused;
  const bool sending = state_ == SessionState::printing || state_ == SessionState::cancelled ||
                       (paused && queue_.empty() && !console_.empty());
  // In ping-pong a Resend's own ok must come in before the resent line goes, or it would be
  // taken for that line's ok.
  const bool held = synchronising_ || (!advanced_ok_ && resend_oks_due_ > 0);
  while (sending && !held) {
    // Host lines (M110, the prelude, resends, a cancel's cleanup) go first, then console lines,
    // then the program's next.
    const bool from_queue = !queue_.empty();
    const bool from_console = !from_queue && !console_.empty();
    if (paused && !from_console) break;
    if (!from_queue && !from_console && next_command_ >= program_->size()) break;
    const std::string& command = from_queue     ? queue_.front().first
                                 : from_console ? console_.front()
                                                : (*program_)[next_command_].text;
    const std::size_t limit = advanced_ok_ ? static_cast<std::size_t>(std::max(1, free_slots_)) : 1;
    if (in_flight_.size() >= limit) break;
    const std::size_t bytes = frame(static_cast<std::uint64_t>(next_line_), command).size() + 1;
    if (!in_flight_.empty() && bytes_in_flight_ + bytes > config_.rx_buffer_bytes) break;
    if (from_queue) {
      auto [text, counts] = std::move(queue_.front());
      queue_.pop_front();
      send_numbered(text, counts, now);
    } else if (from_console) {
      const std::string text = std::move(console_.front());
      console_.pop_front();
      send_numbered(text, false, now);
    } else {
      send_numbered((*program_)[next_command_++].text, true, now);
    }
  }
  if (in_flight_.empty()) {
    reply_deadline_ = Millis::max();
    if (nothing_to_send() && state_ == SessionState::printing && done_ == total_) {  // an empty file too
      state_ = SessionState::finished;
      events_.push_back({SessionEvent::Kind::finished, static_cast<long long>(done_), {}, {}});
    }
  }
}

void MarlinSession::drop_queue() {
  queue_.clear();
  console_.clear();
  next_command_ = program_->size();
}

void MarlinSession::acknowledge(Millis now, bool sample) {
  if (in_flight_.empty()) return;  // a stray ok: nothing to count
  const InFlight f = in_flight_.front();
  in_flight_.pop_front();
  bytes_in_flight_ -= f.bytes;
  if (f.line >= resend_line_)
    resend_line_ = -1, resend_count_ = 0, repeats_expected_ = 0;   // past a resent line
  if (f.reports_temperature && !f.counts) synchronising_ = false;  // our poke is answered
  if (f.counts) {
    ++done_;
    events_.push_back({SessionEvent::Kind::acknowledged, static_cast<long long>(done_), {}, {}});
  }
  // A reply time sample, unless it says nothing about the link (Karn's rule): a resent line, a
  // slow command, a poke, or a line settled by a poke's reply (its own ok was lost).
  const bool poke = f.reports_temperature && !f.counts;
  if (sample && !f.resent && !f.slow && !poke) sample_reply_time(now - f.sent_at);
  if (!synchronising_) poke_wait_ = Millis(0);
  reply_deadline_ = in_flight_.empty() ? Millis::max() : now + timeout_for_front();
}

void MarlinSession::fail(const std::string& why) {
  if (state_ == SessionState::failed) return;  // the first reason is the one that matters
  state_ = SessionState::failed;
  drop_queue();
  events_.push_back({SessionEvent::Kind::failed, 0, why, {}});
}

void MarlinSession::handle_ok(const MarlinReply& r, Millis now) {
  if (r.temperatures.hotend) events_.push_back({SessionEvent::Kind::temperatures, 0, {}, r.temperatures});
  if (r.buffer_free) {
    advanced_ok_ = true;
    free_slots_ = *r.buffer_free;
  }
  if (r.line) {  // ADVANCED_OK: line N and every line before it are done
    while (!in_flight_.empty() && in_flight_.front().line <= *r.line) acknowledge(now);
  } else if (r.temperatures.hotend) {
    // M105's reply: done up to the first M105 in flight. While pokes are out nothing else is
    // sent, so a reply to any poke settles them all: the first one's reply may be the lost one.
    long long through = -1;
    for (const InFlight& f : in_flight_) {
      if (!f.reports_temperature) continue;
      through = f.line;
      if (!synchronising_) break;
    }
    while (!in_flight_.empty() && in_flight_.front().line <= through) acknowledge(now, false);
  } else if (resend_oks_due_ > 0) {
    seen_ok_after_resend_ = true;
    if (--resend_oks_due_ == 0) resend_ok_deadline_ = Millis::max();
  } else if (!advanced_ok_) {
    acknowledge(now);
  }  // else: ADVANCED_OK firmware's plain ok answers a Resend or an unnumbered command
}

void MarlinSession::handle_resend(long long line, Millis now) {
  const bool genuine = checksum_error_;
  checksum_error_ = false;
  if (!advanced_ok_ && expect_ok_after_resend_) {
    if (resend_oks_due_++ == 0) resend_ok_deadline_ = now + config_.resend_ok_wait;
  }
  // Until "N0 M110 N0" is acknowledged the firmware still counts from the previous numbering (the
  // last print's, or 0 after a connect): a request then says the M110 line did not take. It goes
  // again: it resets the count, so sending it twice is always safe. (Found by the soak: a corrupted
  // M110 failed a print asking for "line 8922", or stalled it for the reply timeout on "Resend: 1".)
  if (!in_flight_.empty() && in_flight_.front().line == 0 && sent_.count(0)) line = 0;
  // Each line that was in flight behind the bad one draws the same request: repeats.
  if (line == resend_line_ && repeats_expected_ > 0 && !genuine) {
    --repeats_expected_;
    return;
  }
  if (line != resend_line_) resend_line_ = line, resend_count_ = 0;
  if (++resend_count_ > config_.max_resends_of_one_line) {
    fail("line " + std::to_string(line) + " was rejected " + std::to_string(config_.max_resends_of_one_line) +
         " times: check the cable and the baud rate");
    return;
  }
  auto it = sent_.find(line);
  if (it == sent_.end() && line == next_line_) {  // it wants the line that goes next: nothing to rewind
    while (!in_flight_.empty() && in_flight_.back().line >= line) in_flight_.pop_back();
    return;
  }
  if (it == sent_.end()) {
    fail("the printer asked for line " + std::to_string(line) + ", which was never sent or is too old");
    return;
  }
  events_.push_back({SessionEvent::Kind::resend, line, {}, {}});
  // Lines before `line` were taken; everything from `line` on goes again, in order.
  std::deque<std::pair<std::string, bool>> again;
  for (auto s = it; s != sent_.end(); ++s) again.push_back(s->second);
  resent_ += again.size();
  repeats_expected_ = 0;
  while (!in_flight_.empty() && in_flight_.back().line >= line) {
    if (in_flight_.back().line > line) ++repeats_expected_;
    bytes_in_flight_ -= in_flight_.back().bytes;
    in_flight_.pop_back();
  }
  if (in_flight_.empty()) synchronising_ = false;  // a poke behind the bad line was discarded too
  sent_.erase(it, sent_.end());
  queue_.insert(queue_.begin(), again.begin(), again.end());
  next_line_ = line;
  resent_below_ = line + static_cast<long long>(again.size());
}

void MarlinSession::listen(const MarlinReply& r) {
  using K = SessionEvent::Kind;
  if (r.temperatures.hotend || r.temperatures.bed)
    events_.push_back({K::temperatures, 0, {}, r.temperatures});
  if (r.kind == ReplyKind::error) events_.push_back({K::error, 0, r.text, {}});
  if (r.kind == ReplyKind::start) events_.push_back({K::reset, 0, "the printer restarted", {}});
  if (r.kind == ReplyKind::firmware) events_.push_back({K::firmware, 0, r.name, {}});
  if (r.kind == ReplyKind::capability && r.enabled) events_.push_back({K::capability, 0, r.name, {}});
  if (r.kind == ReplyKind::ok) ++oks_heard_;
}

void MarlinSession::listen_tick(Millis now) {
  if (!config_.autoreport_temperature && (!last_poll_ || now - *last_poll_ >= config_.idle_poll)) {
    output_ += "M105\n";  // unnumbered: no line number to keep in step between prints
    last_poll_ = now;
  }
  if (lost_ || now - last_heard_ <= config_.idle_silence_limit) return;
  lost_ = true;
  events_.push_back(
      {SessionEvent::Kind::timeout,
       0,
       "the printer stopped answering (nothing heard for " +
           std::to_string(
               std::chrono::duration_cast<std::chrono::seconds>(config_.idle_silence_limit).count()) +
           " s between prints)",
       {}});
}

void MarlinSession::handle(const MarlinReply& r, Millis now) {
  using K = SessionEvent::Kind;
  if (state_ == SessionState::idle) return listen(r);
  switch (r.kind) {
    case ReplyKind::ok:
      handle_ok(r, now);
      break;
    case ReplyKind::resend:
      handle_resend(*r.line, now);
      break;
    case ReplyKind::busy:
      if (!in_flight_.empty()) reply_deadline_ = std::max(reply_deadline_, now + config_.busy_timeout);
      break;
    case ReplyKind::start:
      if (state_ == SessionState::printing || state_ == SessionState::paused) {
        events_.push_back({K::reset, 0, "the printer restarted", {}});
        fail("the printer restarted during the print: the print is lost");
      }
      break;
    case ReplyKind::error:
      events_.push_back({K::error, 0, r.text, {}});
      if (r.text.find("hecksum") != std::string::npos)
        checksum_error_ = true;  // "checksum mismatch", "No Checksum"
      if (r.fatal) fail(r.text);
      break;
    case ReplyKind::temperature:
      events_.push_back({K::temperatures, 0, {}, r.temperatures});
      // Marlin reports each second while it waits for a temperature: it is working, not lost.
      if (!in_flight_.empty() && in_flight_.front().waits_for_heat)
        reply_deadline_ = std::max(reply_deadline_, now + config_.busy_timeout);
      break;
    case ReplyKind::firmware:
      events_.push_back({K::firmware, 0, r.name, {}});
      break;
    case ReplyKind::capability:
      if (r.enabled) events_.push_back({K::capability, 0, r.name, {}});
      break;
    case ReplyKind::action:
      events_.push_back({K::action, 0, r.name, {}});
      break;
    case ReplyKind::wait:
    case ReplyKind::other:
      break;
  }
  if (state_ != SessionState::failed) pump(now);
}

void MarlinSession::on_receive(std::string_view bytes, Millis now) {
  last_heard_ += host_gap_.looked(now);
  if (!bytes.empty()) last_heard_ = std::max(last_heard_, now);
  partial_.append(bytes);
  std::size_t start = 0;
  for (std::size_t nl = partial_.find('\n'); nl != std::string::npos; nl = partial_.find('\n', start)) {
    handle(parse_reply(std::string_view(partial_).substr(start, nl - start)), now);
    start = nl + 1;
  }
  partial_.erase(0, start);
  if (partial_.size() > 4096) partial_.clear();  // a line that long is noise, not Marlin
}

void MarlinSession::on_tick(Millis now) {
  last_heard_ += host_gap_.looked(now);  // silence counts only while the host was there to hear
  if (state_ == SessionState::idle) return listen_tick(now);
  if (state_ == SessionState::failed) return;
  if (resend_oks_due_ > 0 && now >= resend_ok_deadline_) {  // this firmware sends no ok after Resend
    resend_oks_due_ = 0;
    resend_ok_deadline_ = Millis::max();
    if (config_.ok_after_resend == SessionConfig::OkAfterResend::detect && !seen_ok_after_resend_ &&
        ++resend_oks_missed_ >= 2)
      expect_ok_after_resend_ = false;
    pump(now);
  }
  if (state_ == SessionState::cancelled && now >= next_m108_) {
    const bool heating =
        std::any_of(in_flight_.begin(), in_flight_.end(), [](const InFlight& f) { return f.waits_for_heat; });
    if (heating)
      break_heating_wait(now);
    else
      next_m108_ = Millis::max();
  }
  check_silence(now);
  if (state_ == SessionState::failed || now < reply_deadline_ || in_flight_.empty()) return;
  events_.push_back({SessionEvent::Kind::timeout, in_flight_.front().line, "no reply from the printer", {}});
  // The next poke waits twice as long (RFC 6298 §5.5), at most poke_interval.
  poke_wait_ =
      poke_wait_.count() == 0 ? timeout_for_front() : std::min(2 * poke_wait_, config_.poke_interval);
  poke_wait_ = std::max(poke_wait_, Millis(1));  // never a busy loop
  synchronising_ = true;
  repeats_expected_ = 0;
  ++pokes_;
  send_numbered("M105", false, now);
  reply_deadline_ = now + std::min(2 * poke_wait_, std::max(poke_wait_, config_.poke_interval));
}

void MarlinSession::check_silence(Millis now) {
  if (!synchronising_ || in_flight_.empty()) return;
  Millis limit = config_.silence_limit;
  if (state_ == SessionState::cancelled)
    limit = std::min(limit, config_.cancel_silence_limit);
  else if (in_flight_.front().slow)
    limit += config_.reply_timeout;
  if (now - last_heard_ < limit) return;
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(now - last_heard_).count();
  fail("the printer stopped answering after line " + std::to_string(done_) + ": nothing heard for " +
       std::to_string(seconds) + " s, " + std::to_string(pokes_) + " M105 pokes unanswered");
}

std::string MarlinSession::take_output() {
  return std::exchange(output_, {});
}
std::vector<SessionEvent> MarlinSession::take_events() {
  return std::exchange(events_, {});
}

}  // namespace salient::protocol::marlin
