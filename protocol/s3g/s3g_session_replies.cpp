// S3gSession's side of the replies: what each reply code and each query's answer mean, and the
// ring accounting — the actions accepted, those the board has started (build stats' `line`), and
// the snapshot that settles a doubt (was a lost reply's action queued?) or finds a reset.
#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

#include "protocol/s3g/s3g_codes.hpp"
#include "protocol/s3g/s3g_session.hpp"

namespace salient::protocol::s3g {

std::size_t S3gSession::done_for(std::size_t program_actions) const {
  if (program_actions >= program_->actions.size()) return program_->commands;
  return std::max(resume_from_, program_->command_of(program_actions));
}

std::size_t S3gSession::started_program_actions() const {
  const std::size_t started = have_baseline_ ? last_line_ - line_base_ : 0;
  const std::size_t past_prelude = started > prelude_.size() ? started - prelude_.size() : 0;
  const std::size_t known = std::min(start_action_ + past_prelude, next_action_);
  // Build stats come once a second; the ring bounds it better between them: it holds at most
  // ring_bytes, so of the accepted actions only a suffix that fits in it can be unstarted — an
  // action whose bytes and those after it exceed the ring had left it (FIFO), and all before it.
  std::size_t bytes = 0;
  for (std::size_t k = next_action_; k > std::max(known, start_action_); --k) {
    bytes += program_->actions[k - 1].size();
    if (bytes > config_.ring_bytes) return k;
  }
  return known;
}

void S3gSession::on_reply(std::string_view payload, Millis now) {
  Packet p = std::move(*in_flight_packet_);
  in_flight_packet_.reset();
  const auto code = static_cast<std::uint8_t>(payload[0]);
  if (!is_reply_code(code)) {
    in_flight_packet_ = std::move(p);
    on_garbled(now, "not a reply");
    return;
  }
  const std::string name(reply_name(code));
  ReplyAction act = action_of(code);
  // Our packets are never longer than 32 bytes: "too big" means noise hit the length byte.
  if (static_cast<Reply>(code) == Reply::packet_too_big && p.payload.size() <= kMaxPayload)
    act = ReplyAction::resend;
  switch (act) {
    case ReplyAction::accept:
      try {
        on_accept(p, payload.substr(1), now);
        garbled_run_ = 0;
      } catch (const std::out_of_range&) {
        in_flight_packet_ = std::move(p);
        on_garbled(now, "short reply");
      }
      return;
    case ReplyAction::resend:
      if (!printing_phase() && !ending_ && p.purpose == Purpose::temperature) return;
      if (p.purpose == Purpose::pause_toggle) {  // the reply may be a stray's: build stats decide
        stats_fresh_ = false;
        quiet_ = true, quiet_until_ = now + config_.quiet_gap;
        return;
      }
      if (p.purpose == Purpose::action && p.counted && printing_phase() && have_baseline_) {
        // Noise that hit a packet's length leaves stray bytes, each answered 80, and one of
        // them may be taken for this packet's reply: the ring says whether it was queued.
        ++p.tries, ++resent_;
        events_.push_back({SessionEvent::Kind::resend, done_, {}, {}});
        if (p.tries > config_.max_resends) {
          fail("no packet got through after " + std::to_string(config_.max_resends) + " resends (" + name +
               ")");
          return;
        }
        quiet_ = true, quiet_until_ = now + config_.quiet_gap;
        snapshot_ = Snapshot{};
        snapshot_->doubtful = std::move(p);
        snapshot_->after_error = true;
        return;
      }
      retry(std::move(p), now);
      return;
    case ReplyAction::wait_resend:
      if (p.purpose == Purpose::action && p.counted) {
        need_room_ = true;
        next_room_poll_ = now, room_polls_ = 0;
      } else if (p.purpose == Purpose::action) {  // cleanup behind a full ring: try again shortly
        control_.push_front(std::move(p));
        control_not_before_ = now + config_.buffer_poll;
      } else {
        retry(std::move(p), now);
      }
      return;
    case ReplyAction::stop:
      if (printing_phase() || ending_) {
        ending_ = false, control_.clear();
        if (static_cast<Reply>(code) == Reply::cancelled)
          end(SessionState::cancelled, name);
        else
          fail(name);
      } else {
        events_.push_back({SessionEvent::Kind::error, 0, name, {}});
        if (handshaking_) handshaking_ = false, control_.clear();
      }
      return;
    case ReplyAction::fatal:
      if (p.purpose == Purpose::advanced_version) {  // not Sailfish: MakerBot's own firmware
        handshaking_ = false, handshake_done_ = true;
        firmware_name_ = "MakerBot firmware " + std::to_string(firmware_version_ / 100) + "." +
                         std::to_string(firmware_version_ % 100);
        events_.push_back({SessionEvent::Kind::firmware, 0, firmware_name_, {}});
        return;
      }
      if (printing_phase() || ending_) {
        ending_ = false, control_.clear();
        fail("the printer answered " + name);
      } else {
        events_.push_back({SessionEvent::Kind::error, 0, "the printer answered " + name, {}});
      }
      return;
  }
}

void S3gSession::on_accept(const Packet& p, std::string_view data, Millis now) {
  std::size_t at = 0;
  switch (p.purpose) {
    case Purpose::action:
      if (p.counted && printing_phase()) accept_action(p);
      if (p.counted && state_ == SessionState::printing && next_action_ >= program_->actions.size())
        next_stats_ =
            std::min(next_stats_, now + config_.pause_check);  // soon: has the board started it all?
      return;
    case Purpose::version:
      firmware_version_ = get_u16(data, at);
      return;
    case Purpose::advanced_version: {
      firmware_version_ = get_u16(data, at);
      get_u16(data, at);
      variant_ = get_u8(data, at);
      const std::string v =
          std::to_string(firmware_version_ / 100) + "." + std::to_string(firmware_version_ % 100);
      firmware_name_ = variant_ == 0x80 ? "Sailfish " + v
                                        : "s3g firmware " + v + " (variant " + std::to_string(variant_) + ")";
      handshaking_ = false, handshake_done_ = true;
      events_.push_back({SessionEvent::Kind::firmware, 0, firmware_name_, {}});
      return;
    }
    case Purpose::buffer_space: {
      const std::uint32_t free = get_u32(data, at);
      if (snapshot_ && snapshot_->step == 1) {
        snapshot_->free = free;
        snapshot_->step = 2;
      } else if (need_room_ && current_ && free >= current_->payload.size()) {
        need_room_ = false;
        retry_ = *current_;
      }
      return;
    }
    case Purpose::build_stats: {
      BuildStats s;
      s.state = get_u8(data, at), s.hours = get_u8(data, at), s.minutes = get_u8(data, at);
      s.line = get_u32(data, at);
      if (snapshot_ && snapshot_->step == 0) {
        snapshot_->l1 = s.line;
        snapshot_->step = 1;
      } else if (snapshot_ && snapshot_->step == 2) {
        if (s.line == snapshot_->l1) {
          on_stats(s, now);
          if (snapshot_) resolve(now);
          return;
        }
        snapshot_->step = 0;
        if (++snapshot_->attempts > config_.snapshot_attempts) {
          fail("the printer's buffer never held still for a consistent reading");
          return;
        }
      }
      on_stats(s, now);
      return;
    }
    case Purpose::temperature: {
      const double t = get_i16(data, at);
      const auto c = static_cast<ToolCommand>(p.payload[2]);
      SessionEvent e{SessionEvent::Kind::temperatures, done_, {}, {}};
      if (c == ToolCommand::get_temperature) temps_.hotend = t;
      if (c == ToolCommand::platform_temperature) temps_.bed = t;
      if (c == ToolCommand::target_temperature) {
        temps_.hotend_target = t;
        e.temperatures.hotend = temps_.hotend, e.temperatures.hotend_target = t;
        if (e.temperatures.hotend) events_.push_back(e);
      }
      if (c == ToolCommand::platform_target) {
        temps_.bed_target = t;
        e.temperatures.bed = temps_.bed, e.temperatures.bed_target = t;
        if (e.temperatures.bed) events_.push_back(e);
      }
      return;
    }
    case Purpose::pause_toggle:
      return;  // build stats confirm it
    case Purpose::abort:
    case Purpose::extended_stop:
      accepted_sizes_.clear();  // the ring is empty now
      return;
  }
}

void S3gSession::accept_action(const Packet& p) {
  accepted_sizes_.push_back(p.payload.size());
  ++accepted_count_;
  current_.reset();
  if (prelude_next_ < prelude_.size()) {
    ++prelude_next_;
    return;
  }
  ++next_action_;
  const std::size_t done = done_for(next_action_);
  if (done > done_) {
    done_ = done;
    events_.push_back({SessionEvent::Kind::acknowledged, done_, {}, {}});
  }
}

void S3gSession::on_stats(const BuildStats& s, Millis now) {
  (void)now;
  stats_fresh_ = true;
  if (!printing_phase() || ending_) return;
  if (!have_baseline_) return;  // the baseline snapshot sets it
  if (s.line < last_line_ || (seen_building_ && s.state == BuildStats::none)) {
    reset_detected();
    return;
  }
  last_line_ = s.line;
  if (s.state != BuildStats::none) seen_building_ = true;
  const std::size_t started = s.line - line_base_;
  while (!accepted_sizes_.empty() && accepted_base_ < started) accepted_sizes_.pop_front(), ++accepted_base_;
  const std::size_t doubt = snapshot_ && snapshot_->doubtful ? 1 : 0;
  if (started > accepted_count_ + doubt) {
    fail("the printer ran " + std::to_string(started) + " actions but only " +
         std::to_string(accepted_count_) + " were sent: is another host sending?");
    return;
  }
  if (want_paused_) {
    const bool paused = s.state == BuildStats::paused;
    const bool settled = *want_paused_
                             ? paused
                             : !paused && (s.state == BuildStats::running || s.state == state_before_pause_);
    if (settled) {
      board_paused_ = paused;
      state_ = paused ? SessionState::paused : SessionState::printing;
      want_paused_.reset();
      toggled_at_.reset();
      events_.push_back({paused ? SessionEvent::Kind::paused : SessionEvent::Kind::resumed, done_, {}, {}});
    }
  } else if (!board_paused_) {
    state_before_pause_ = s.state;
  }
  if (state_ == SessionState::printing && !current_ && !snapshot_ && prelude_next_ >= prelude_.size() &&
      next_action_ >= program_->actions.size() && started >= accepted_count_)
    end(SessionState::finished, {});
}

void S3gSession::resolve(Millis now) {
  Snapshot snap = std::move(*snapshot_);
  snapshot_.reset();
  const std::size_t occupancy = config_.ring_bytes - std::min<std::size_t>(snap.free, config_.ring_bytes);
  if (!have_baseline_) {
    if (occupancy != 0) {  // a previous print is still running out: wait for an empty ring
      if (snap.attempts == 0)
        events_.push_back(
            {SessionEvent::Kind::error, done_, "the printer's buffer is not empty: waiting for it", {}});
      snapshot_ = Snapshot{};
      snapshot_->attempts = 1;
      next_room_poll_ = now + config_.buffer_poll;
      return;
    }
    line_base_ = last_line_ = snap.l1;
    have_baseline_ = true;
    return;
  }
  const std::size_t started = snap.l1 - line_base_;
  const std::size_t expected =
      std::accumulate(accepted_sizes_.begin(), accepted_sizes_.end(), std::size_t{0});
  if (snap.doubtful) {
    const std::size_t size = snap.doubtful->payload.size();
    if (started == accepted_count_ + 1 || occupancy == expected + size) {
      ++doubts_queued_;
      accept_action(*snap.doubtful);
      while (!accepted_sizes_.empty() && accepted_base_ < started)
        accepted_sizes_.pop_front(), ++accepted_base_;
      if (state_ == SessionState::printing && next_action_ >= program_->actions.size())
        next_stats_ = std::min(next_stats_, now + config_.pause_check);
      return;
    }
    if (occupancy == expected) {
      if (!snap.after_error) ++doubts_not_queued_, ++resent_;
      retry_ = std::move(snap.doubtful);  // the board never took it: this is its first run
      return;
    }
  } else if (occupancy == expected) {
    return;
  }
  if (occupancy < expected) {  // the board lost what it had queued
    reset_detected();
    return;
  }
  if (++snap.attempts > config_.snapshot_attempts) {
    fail("the printer's buffer holds " + std::to_string(occupancy) + " bytes where " +
         std::to_string(expected) + " were expected: cannot tell what it queued");
    return;
  }
  snap.step = 0;
  snapshot_ = std::move(snap);
}

void S3gSession::reset_detected() {
  done_ = std::max(resume_from_, done_for(started_program_actions()));
  events_.push_back({SessionEvent::Kind::reset, done_, "the printer reset", {}});
  fail("the printer reset");
}

}  // namespace salient::protocol::s3g
