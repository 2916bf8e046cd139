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
// A silence with lines in flight sends an M105 poke and holds further lines until it is answered.
#include "protocol/marlin/marlin_session.hpp"

#include <utility>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol::marlin {
namespace {

bool is_m105(const std::string& command) { return command == "M105" || command.rfind("M105 ", 0) == 0; }

}  // namespace

MarlinSession::MarlinSession(SessionConfig config)
    : config_(config), expect_ok_after_resend_(config.ok_after_resend != SessionConfig::OkAfterResend::no) {}

void MarlinSession::begin(const std::vector<std::string>& gcode, Millis now, std::size_t resume_from,
                          const std::vector<std::string>& prelude) {
  queue_.clear();
  sent_.clear();
  in_flight_.clear();
  bytes_in_flight_ = 0;
  next_line_ = 0;
  done_ = total_ = 0;
  queue_.emplace_back("M110 N0", false);  // the firmware now expects line 1 next
  for (const std::string& line : prelude) {
    std::string command = strip_comment(line);
    if (!command.empty()) queue_.emplace_back(std::move(command), false);
  }
  for (const std::string& line : gcode) {
    std::string command = strip_comment(line);
    if (command.empty()) continue;
    if (total_++ < resume_from) continue;
    queue_.emplace_back(std::move(command), true);
  }
  done_ = std::min(resume_from, total_);
  state_ = SessionState::printing;
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

void MarlinSession::cancel(const std::vector<std::string>& cleanup, Millis now) {
  if (state_ != SessionState::printing && state_ != SessionState::paused) return;
  queue_.clear();
  for (const std::string& line : cleanup) {
    std::string command = strip_comment(line);
    if (!command.empty()) queue_.emplace_back(std::move(command), false);
  }
  state_ = SessionState::cancelled;
  pump(now);
}

void MarlinSession::emergency_stop() {
  output_ += "M112\n";
  queue_.clear();
  state_ = SessionState::failed;
  events_.push_back({SessionEvent::Kind::failed, 0, "emergency stop", {}});
}

void MarlinSession::send_numbered(const std::string& command, bool counts, Millis now) {
  const long long line = next_line_++;
  const std::string framed = frame(static_cast<std::uint64_t>(line), command) + "\n";
  output_ += framed;
  sent_[line] = {command, counts};
  while (sent_.size() > 256) sent_.erase(sent_.begin());  // Marlin only asks for recent lines
  in_flight_.push_back({line, framed.size(), counts, is_m105(command)});
  bytes_in_flight_ += framed.size();
  reply_deadline_ = now + config_.reply_timeout;
}

void MarlinSession::pump(Millis now) {
  const bool sending = state_ == SessionState::printing || state_ == SessionState::cancelled;
  // In ping-pong a Resend's own ok must come in before the resent line goes, or it would be
  // taken for that line's ok.
  const bool held = synchronising_ || (!advanced_ok_ && resend_oks_due_ > 0);
  while (sending && !queue_.empty() && !held) {
    const std::size_t limit = advanced_ok_ ? static_cast<std::size_t>(std::max(1, free_slots_)) : 1;
    if (in_flight_.size() >= limit) break;
    const std::size_t bytes = frame(static_cast<std::uint64_t>(next_line_), queue_.front().first).size() + 1;
    if (!in_flight_.empty() && bytes_in_flight_ + bytes > config_.rx_buffer_bytes) break;
    auto [command, counts] = queue_.front();
    queue_.pop_front();
    send_numbered(command, counts, now);
  }
  if (in_flight_.empty()) {
    reply_deadline_ = Millis::max();
    if (queue_.empty() && state_ == SessionState::printing && total_ > 0 && done_ == total_) {
      state_ = SessionState::finished;
      events_.push_back({SessionEvent::Kind::finished, static_cast<long long>(done_), {}, {}});
    }
  }
}

void MarlinSession::acknowledge(Millis now) {
  if (in_flight_.empty()) return;  // a stray ok: nothing to count
  const InFlight f = in_flight_.front();
  in_flight_.pop_front();
  bytes_in_flight_ -= f.bytes;
  if (f.line >= resend_line_) resend_line_ = -1, resend_count_ = 0, repeats_expected_ = 0;  // past a resent line
  if (f.reports_temperature && !f.counts) synchronising_ = false;  // our poke is answered
  if (f.counts) {
    ++done_;
    events_.push_back({SessionEvent::Kind::acknowledged, static_cast<long long>(done_), {}, {}});
  }
  reply_deadline_ = in_flight_.empty() ? Millis::max() : now + config_.reply_timeout;
}

void MarlinSession::fail(const std::string& why) {
  if (state_ == SessionState::failed) return;  // the first reason is the one that matters
  state_ = SessionState::failed;
  queue_.clear();
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
    while (!in_flight_.empty() && in_flight_.front().line <= through) acknowledge(now);
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
}

void MarlinSession::handle(const MarlinReply& r, Millis now) {
  using K = SessionEvent::Kind;
  switch (r.kind) {
    case ReplyKind::ok:
      handle_ok(r, now);
      break;
    case ReplyKind::resend:
      handle_resend(*r.line, now);
      break;
    case ReplyKind::busy:
      if (!in_flight_.empty()) reply_deadline_ = now + config_.busy_timeout;
      break;
    case ReplyKind::start:
      if (state_ == SessionState::printing || state_ == SessionState::paused) {
        events_.push_back({K::reset, 0, "the printer restarted", {}});
        fail("the printer restarted during the print: the print is lost");
      }
      break;
    case ReplyKind::error:
      events_.push_back({K::error, 0, r.text, {}});
      if (r.text.find("hecksum") != std::string::npos) checksum_error_ = true;  // "checksum mismatch", "No Checksum"
      if (r.fatal) fail(r.text);
      break;
    case ReplyKind::temperature:
      events_.push_back({K::temperatures, 0, {}, r.temperatures});
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
  if (state_ == SessionState::failed) return;
  if (resend_oks_due_ > 0 && now >= resend_ok_deadline_) {  // this firmware sends no ok after Resend
    resend_oks_due_ = 0;
    resend_ok_deadline_ = Millis::max();
    if (config_.ok_after_resend == SessionConfig::OkAfterResend::detect && !seen_ok_after_resend_ &&
        ++resend_oks_missed_ >= 2)
      expect_ok_after_resend_ = false;
    pump(now);
  }
  if (now < reply_deadline_ || in_flight_.empty()) return;
  events_.push_back({SessionEvent::Kind::timeout, in_flight_.front().line, "no reply from the printer", {}});
  synchronising_ = true;
  repeats_expected_ = 0;
  ++pokes_;
  send_numbered("M105", false, now);
}

std::string MarlinSession::take_output() { return std::exchange(output_, {}); }
std::vector<SessionEvent> MarlinSession::take_events() { return std::exchange(events_, {}); }

}  // namespace salient::protocol::marlin
