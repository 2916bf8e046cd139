// MarlinSession. Flow control: one line in flight (ping-pong) until the firmware shows
// ADVANCED_OK ("ok N P B"); then up to B lines, never more bytes than its receive buffer.
// Resends: Marlin discards everything after a bad line and asks again for each line that
// followed ("Resend: N" + "ok" each time): we rewind once to N, keep the lines before N in flight
// (they were taken), swallow the oks that come with resend requests, and give up after
// max_resends_of_one_line requests for the same line. A silence with lines in flight sends an
// M105 poke; its ok means every line sent before it was processed (their oks were lost).
#include "protocol/marlin/marlin_session.hpp"

#include <algorithm>
#include <utility>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol::marlin {

MarlinSession::MarlinSession(SessionConfig config) : config_(config) {}

void MarlinSession::begin(const std::vector<std::string>& gcode, Millis now) {
  queue_.clear();
  sent_.clear();
  in_flight_.clear();
  bytes_in_flight_ = 0;
  next_line_ = 0;
  done_ = total_ = 0;
  queue_.emplace_back("M110 N0", false);  // the firmware now expects line 1 next
  for (const std::string& line : gcode) {
    std::string command = strip_comment(line);
    if (command.empty()) continue;
    queue_.emplace_back(std::move(command), true);
    ++total_;
  }
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
  in_flight_.push_back({line, framed.size(), counts});
  bytes_in_flight_ += framed.size();
  deadline_ = now + config_.reply_timeout;
}

void MarlinSession::pump(Millis now) {
  const bool sending = state_ == SessionState::printing || state_ == SessionState::cancelled;
  while (sending && !queue_.empty() && !synchronising_) {
    const std::size_t limit = advanced_ok_ ? static_cast<std::size_t>(std::max(1, free_slots_)) : 1;
    if (in_flight_.size() >= limit) break;
    const std::size_t bytes = frame(static_cast<std::uint64_t>(next_line_), queue_.front().first).size() + 1;
    if (!in_flight_.empty() && bytes_in_flight_ + bytes > config_.rx_buffer_bytes) break;
    auto [command, counts] = queue_.front();
    queue_.pop_front();
    send_numbered(command, counts, now);
  }
  if (in_flight_.empty()) {
    deadline_ = Millis::max();
    if (queue_.empty() && state_ == SessionState::printing && total_ > 0 && done_ == total_) {
      state_ = SessionState::finished;
      events_.push_back({SessionEvent::Kind::finished, static_cast<long long>(done_), {}, {}});
    }
  }
}

void MarlinSession::acknowledge(Millis now) {
  if (in_flight_.empty()) return;  // a stray ok (after a poke round, say): nothing to count
  const InFlight f = in_flight_.front();
  in_flight_.pop_front();
  bytes_in_flight_ -= f.bytes;
  if (f.line >= resend_line_) resend_line_ = -1, resend_count_ = 0, repeats_expected_ = 0;  // past a resent line
  if (f.counts) {
    ++done_;
    events_.push_back({SessionEvent::Kind::acknowledged, static_cast<long long>(done_), {}, {}});
  }
  deadline_ = in_flight_.empty() ? Millis::max() : now + config_.reply_timeout;
}

void MarlinSession::fail(const std::string& why) {
  state_ = SessionState::failed;
  queue_.clear();
  events_.push_back({SessionEvent::Kind::failed, 0, why, {}});
}

void MarlinSession::handle(const MarlinReply& r, Millis now) {
  using K = SessionEvent::Kind;
  switch (r.kind) {
    case ReplyKind::ok:
      if (r.temperatures.hotend) events_.push_back({K::temperatures, 0, {}, r.temperatures});
      if (r.buffer_free) {
        advanced_ok_ = true;
        free_slots_ = *r.buffer_free;
      }
      if (oks_to_swallow_ > 0) {
        --oks_to_swallow_;
        break;
      }
      if (synchronising_) {  // the poke's ok: everything sent before it was processed
        synchronising_ = false;
        while (!in_flight_.empty()) acknowledge(now);
      } else {
        acknowledge(now);
      }
      break;
    case ReplyKind::resend: {
      const long long line = *r.line;
      if (config_.ok_after_resend) ++oks_to_swallow_;
      // Each line that was in flight behind the bad one draws the same request: repeats.
      if (line == resend_line_ && repeats_expected_ > 0) {
        --repeats_expected_;
        break;
      }
      if (line != resend_line_) resend_line_ = line, resend_count_ = 0;
      if (++resend_count_ > config_.max_resends_of_one_line) {
        fail("line " + std::to_string(line) + " was rejected " + std::to_string(config_.max_resends_of_one_line) +
             " times: check the cable and the baud rate");
        break;
      }
      auto it = sent_.find(line);
      if (it == sent_.end()) {
        fail("the printer asked for line " + std::to_string(line) + ", which was never sent or is too old");
        break;
      }
      events_.push_back({K::resend, line, {}, {}});
      // Lines before `line` were taken; everything from `line` on goes again, in order.
      std::deque<std::pair<std::string, bool>> again;
      for (auto s = it; s != sent_.end(); ++s) again.push_back(s->second);
      repeats_expected_ = 0;
      while (!in_flight_.empty() && in_flight_.back().line >= line) {
        if (in_flight_.back().line > line) ++repeats_expected_;
        bytes_in_flight_ -= in_flight_.back().bytes;
        in_flight_.pop_back();
      }
      sent_.erase(it, sent_.end());
      queue_.insert(queue_.begin(), again.begin(), again.end());
      next_line_ = line;
      pump(now);
      break;
    }
    case ReplyKind::busy:
      if (!in_flight_.empty()) deadline_ = now + config_.busy_timeout;
      break;
    case ReplyKind::start:
      if (state_ == SessionState::printing || state_ == SessionState::paused) {
        events_.push_back({K::reset, 0, "the printer restarted", {}});
        fail("the printer restarted during the print: the print is lost");
      }
      break;
    case ReplyKind::error:
      events_.push_back({K::error, 0, r.text, {}});
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
  if (now < deadline_ || in_flight_.empty() || state_ == SessionState::failed) return;
  events_.push_back({SessionEvent::Kind::timeout, in_flight_.front().line, "no reply from the printer", {}});
  synchronising_ = true;
  send_numbered("M105", false, now);
}

std::string MarlinSession::take_output() { return std::exchange(output_, {}); }
std::vector<SessionEvent> MarlinSession::take_events() { return std::exchange(events_, {}); }

}  // namespace salient::protocol::marlin
