#include "protocol/s3g/s3g_session.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "protocol/s3g/s3g_codes.hpp"
#include "protocol/s3g/x3g_commands.hpp"

namespace salient::protocol::s3g {
namespace {

std::string query(Query q) {
  return std::string(1, static_cast<char>(q));
}

std::string with_host_version(Query q, std::uint16_t host) {
  std::string p = query(q);
  put_u16(p, host);
  return p;
}

std::string tool_query(ToolCommand c) {
  std::string p = query(Query::tool_query);
  put_u8(p, 0);
  put_u8(p, static_cast<std::uint8_t>(c));
  return p;
}

std::string tool_action(ToolCommand c, std::int16_t value) {
  std::string p(1, static_cast<char>(Action::tool_action));
  put_u8(p, 0);
  put_u8(p, static_cast<std::uint8_t>(c));
  put_u8(p, 2);
  put_i16(p, value);
  return p;
}

constexpr ToolCommand kTemperatureQueries[4] = {ToolCommand::get_temperature, ToolCommand::target_temperature,
                                                ToolCommand::platform_temperature,
                                                ToolCommand::platform_target};

std::string seconds(Millis m) {
  return std::to_string(m.count() / 1000) + "." + std::to_string(m.count() % 1000 / 100) + " s";
}

}  // namespace

S3gSession::S3gSession(SessionConfig config) : config_(config) {}

std::vector<std::string> S3gSession::heaters_off() {
  return {tool_action(ToolCommand::set_temperature, 0),
          tool_action(ToolCommand::set_platform_temperature, 0)};
}

std::vector<std::string> S3gSession::cancel_cleanup() {
  std::vector<std::string> out = heaters_off();
  out.push_back(std::string{static_cast<char>(Action::enable_axes), 0x1F});  // bit 7 clear: X Y Z A B off
  return out;
}

void S3gSession::handshake(Millis now) {
  handshaking_ = true;
  handshake_done_ = false;
  heard(now);
  control_.push_back({with_host_version(Query::version, config_.host_version), Purpose::version});
  control_.push_back(
      {with_host_version(Query::advanced_version, config_.host_version), Purpose::advanced_version});
  pump(now);
}

void S3gSession::begin(std::shared_ptr<const X3gProgram> program, Millis now, std::size_t resume_from,
                       std::vector<std::string> prelude) {
  program_ = program ? std::move(program) : std::make_shared<const X3gProgram>();
  for (const std::string& a : prelude)
    if (a.empty() || a.size() > kMaxPayload || static_cast<std::uint8_t>(a[0]) < 128)
      throw std::invalid_argument(
          "s3g prelude: an action payload must be 1…32 bytes and start with an id ≥ 128");
  prelude_ = std::move(prelude);
  state_ = SessionState::printing;
  began_ = true;
  resume_from_ = std::min(resume_from, program_->commands);
  done_ = resume_from_;
  start_action_ = next_action_ = program_->first_action_of(resume_from_);
  prelude_next_ = 0;
  current_.reset(), retry_.reset(), need_room_ = false;
  accepted_sizes_.clear(), accepted_base_ = accepted_count_ = 0;
  have_baseline_ = seen_building_ = false;
  snapshot_ = Snapshot{};  // the ring's baseline: `line` now, and an empty ring
  next_stats_ = now + config_.stats_poll, next_temps_ = now + config_.temperature_poll;
  heard(now);
  pump(now);
}

void S3gSession::pause() {
  if (state_ != SessionState::printing || want_paused_) return;
  if (ending_) return;
  state_ = SessionState::paused;  // nothing more goes until the board confirms either way
  want_paused_ = true;
  stats_fresh_ = false, toggled_at_.reset(), toggles_ = 0;
  next_stats_ = Millis(0);
}

void S3gSession::resume(Millis now) {
  if (state_ != SessionState::paused) return;
  want_paused_ = false;
  stats_fresh_ = false, toggled_at_.reset(), toggles_ = 0;
  next_stats_ = Millis(0);
  pump(now);
}

void S3gSession::cancel(const std::vector<std::string>& cleanup, Millis now, bool clear_ring) {
  if (!printing_phase()) return;
  // A paused board would never run the cleanup behind its queued moves: clear it then too.
  if (board_paused_) clear_ring = true;
  if (clear_ring) done_ = std::max(resume_from_, done_for(started_program_actions()));
  ending_ = true;
  state_ = SessionState::cancelled;
  snapshot_.reset(), current_.reset(), retry_.reset(), want_paused_.reset(), need_room_ = false;
  control_.clear();
  if (clear_ring) control_.push_back({query(Query::abort), Purpose::abort});
  for (const std::string& c : cleanup) control_.push_back({c, Purpose::action});
  pump(now);
}

void S3gSession::emergency_stop(const std::vector<std::string>& cleanup, Millis now) {
  if (!printing_phase() && !ending_) return;
  if (printing_phase()) done_ = std::max(resume_from_, done_for(started_program_actions()));
  ending_ = true;
  state_ = SessionState::cancelled;
  snapshot_.reset(), current_.reset(), retry_.reset(), want_paused_.reset(), need_room_ = false;
  control_.clear();
  // Halt the steppers and clear the ring (bits 0 and 1), then the heaters.
  control_.push_back({std::string{static_cast<char>(Query::extended_stop), 0x03}, Purpose::extended_stop});
  for (const std::string& c : cleanup) control_.push_back({c, Purpose::action});
  pump(now);
}

std::size_t S3gSession::done_for(std::size_t program_actions) const {
  if (program_actions >= program_->actions.size()) return program_->commands;
  return std::max(resume_from_, program_->command_of(program_actions));
}

std::size_t S3gSession::started_program_actions() const {
  const std::size_t started = have_baseline_ ? last_line_ - line_base_ : 0;
  const std::size_t past_prelude = started > prelude_.size() ? started - prelude_.size() : 0;
  return std::min(start_action_ + past_prelude, next_action_);
}

void S3gSession::send(Packet p, Millis now) {
  output_ += frame(p.payload);
  in_flight_packet_ = std::move(p);
  in_flight_ = true;
  reply_deadline_ = now + config_.reply_timeout;
  decoder_.reset();
}

void S3gSession::pump(Millis now) {
  if (in_flight_) return;
  if (quiet_ && now < quiet_until_) return;
  quiet_ = false;
  if (auto p = next_packet(now)) send(std::move(*p), now);
  if (ending_ && !in_flight_ && control_.empty() && !retry_) {
    ending_ = false;
    events_.push_back({SessionEvent::Kind::cancelled, done_, "cancelled", {}});
  }
}

std::optional<S3gSession::Packet> S3gSession::next_packet(Millis now) {
  if (retry_) {
    Packet p = std::move(*retry_);
    retry_.reset();
    return p;
  }
  if (!control_.empty()) {
    if (now < control_not_before_) return std::nullopt;
    Packet p = std::move(control_.front());
    control_.pop_front();
    return p;
  }
  if (!printing_phase()) return std::nullopt;
  const Packet stats{query(Query::build_stats), Purpose::build_stats};
  if (snapshot_) {
    if (now < next_room_poll_ && !have_baseline_) return std::nullopt;  // the ring was busy: wait
    if (snapshot_->step == 1) return Packet{query(Query::buffer_space), Purpose::buffer_space};
    return stats;
  }
  if (want_paused_) {
    if (stats_fresh_ && (!toggled_at_ || now >= *toggled_at_ + config_.pause_confirm)) {
      if (toggles_ >= config_.max_toggles) {
        const bool wanted = *want_paused_;
        events_.push_back(
            {SessionEvent::Kind::error,
             done_,
             wanted ? "the printer did not confirm the pause" : "the printer did not confirm the resume",
             {}});
        want_paused_.reset();
        state_ = board_paused_ ? SessionState::paused : SessionState::printing;
      } else {
        ++toggles_;
        toggled_at_ = now;
        stats_fresh_ = false;
        next_stats_ = now + config_.pause_check;
        return Packet{query(Query::pause), Purpose::pause_toggle};
      }
    } else if (now >= next_stats_) {
      next_stats_ = now + config_.pause_check;
      return stats;
    }
    if (want_paused_) return std::nullopt;
  }
  if (now >= next_stats_) {
    next_stats_ = now + config_.stats_poll;
    return stats;
  }
  if (temp_step_ >= 4 && now >= next_temps_) temp_step_ = 0, next_temps_ = now + config_.temperature_poll;
  if (temp_step_ < 4) return Packet{tool_query(kTemperatureQueries[temp_step_++]), Purpose::temperature};
  if (need_room_) {
    if (now < next_room_poll_) return std::nullopt;
    next_room_poll_ =
        now + (room_polls_++ < config_.fast_polls ? config_.buffer_poll_fast : config_.buffer_poll);
    return Packet{query(Query::buffer_space), Purpose::buffer_space};
  }
  if (state_ != SessionState::printing || current_ || !have_baseline_) return std::nullopt;
  if (prelude_next_ < prelude_.size()) {
    current_ = Packet{prelude_[prelude_next_], Purpose::action, true};
  } else if (next_action_ < program_->actions.size()) {
    current_ = Packet{program_->actions[next_action_], Purpose::action, true};
  } else {
    return std::nullopt;  // all queued: build stats tell when the board has started the last
  }
  return current_;
}

void S3gSession::on_receive(std::string_view bytes, Millis now) {
  if (bytes.empty()) return;
  heard(now);
  lost_ = false;
  if (quiet_) {
    quiet_until_ = now + config_.quiet_gap;  // stale bytes of a doubtful exchange: wait them out
    return;
  }
  for (std::size_t i = 0; i < bytes.size() && in_flight_; ++i) {
    const PacketDecoder::Result r = decoder_.feed(static_cast<std::uint8_t>(bytes[i]));
    if (r.payload) {
      in_flight_ = false;
      on_reply(*r.payload, now);
      if (i + 1 < bytes.size()) quiet_ = true, quiet_until_ = now + config_.quiet_gap;  // more than one reply
    } else if (r.error != PacketDecoder::Error::none) {
      in_flight_ = false;
      on_garbled(now, r.error == PacketDecoder::Error::bad_crc ? "bad CRC" : "bad length");
    }
  }
  // A reply comes as one burst: bytes that made none by byte_timeout after the last were noise.
  if (in_flight_) reply_deadline_ = std::min(reply_deadline_, now + config_.byte_timeout);
  if (in_flight_ && decoder_.in_packet()) reply_deadline_ = now + config_.byte_timeout;
  pump(now);
}

void S3gSession::on_tick(Millis now) {
  if (in_flight_ && now >= reply_deadline_) {
    in_flight_ = false;
    ++timeouts_;
    on_garbled(now, "no reply");
  }
  check_silence(now);
  if (!began_ && !ending_ && !in_flight_ && control_.empty() && !handshaking_ &&
      (!last_poll_ || now - *last_poll_ >= config_.idle_poll)) {
    last_poll_ = now;
    for (ToolCommand c : kTemperatureQueries) control_.push_back({tool_query(c), Purpose::temperature});
  }
  pump(now);
}

void S3gSession::check_silence(Millis now) {
  if (printing_phase() || ending_) {
    if (!(in_flight_ || quiet_) || now - last_heard_ < config_.silence_limit) return;
    const std::string why =
        "the printer stopped answering (nothing heard for " + seconds(now - last_heard_) + ")";
    if (ending_) {
      control_.clear(), in_flight_ = false, quiet_ = false, ending_ = false;
      events_.push_back({SessionEvent::Kind::cancelled, done_, why, {}});
    } else {
      fail(why);
    }
    in_flight_ = false, quiet_ = false;
    return;
  }
  if (!lost_ && last_poll_ && now - last_heard_ >= config_.idle_silence_limit) {
    lost_ = true;
    events_.push_back({SessionEvent::Kind::timeout,
                       0,
                       "the printer stopped answering (nothing heard for " + seconds(now - last_heard_) + ")",
                       {}});
  }
}

// The reply was lost, garbled or late: what the packet did is unknown. Queries are asked again;
// a print action is resolved from the ring before anything else goes.
void S3gSession::on_garbled(Millis now, const char* why) {
  (void)why;
  Packet p = std::move(*in_flight_packet_);
  in_flight_packet_.reset();
  quiet_ = true, quiet_until_ = now + config_.quiet_gap;
  decoder_.reset();
  if (!printing_phase() && !ending_) {
    if (p.purpose == Purpose::version || p.purpose == Purpose::advanced_version) retry_ = std::move(p);
    return;  // listening: a lost temperature goes with the next poll
  }
  const bool check = printing_phase() && have_baseline_ && !ending_;
  switch (p.purpose) {
    case Purpose::action:
      if (p.counted && check) {
        snapshot_ = Snapshot{};
        snapshot_->doubtful = std::move(p);
      } else if (!p.counted) {
        retry_ = std::move(p);  // cleanup (heaters off) may safely run twice
      }
      return;
    case Purpose::pause_toggle:
      stats_fresh_ = false;  // never toggled again blindly: build stats decide
      return;
    case Purpose::build_stats:
    case Purpose::buffer_space:
      if (snapshot_) {
        snapshot_->step = 0;
        return;
      }
      break;
    case Purpose::temperature:
      break;
    default:
      retry_ = std::move(p);
      return;
  }
  // A board deaf for a while may have reset: compare the ring with what it should hold.
  if (check && !snapshot_) snapshot_ = Snapshot{};
}

void S3gSession::retry(Packet p, Millis now) {
  ++p.tries;
  ++resent_;
  events_.push_back({SessionEvent::Kind::resend, done_, {}, {}});
  if (p.tries > config_.max_resends) {
    fail("no packet got through after " + std::to_string(config_.max_resends) + " resends");
    return;
  }
  quiet_ = true, quiet_until_ = now + config_.quiet_gap;
  retry_ = std::move(p);
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

void S3gSession::fail(const std::string& why) {
  if (ending_) {  // a cancel that could not finish is still a cancel, with the reason
    ending_ = false;
    end(SessionState::cancelled, why);
    return;
  }
  end(SessionState::failed, why);
}

void S3gSession::end(SessionState s, const std::string& why) {
  state_ = s;
  current_.reset(), retry_.reset(), snapshot_.reset(), want_paused_.reset(), need_room_ = false;
  control_.clear();
  const auto kind = s == SessionState::finished    ? SessionEvent::Kind::finished
                    : s == SessionState::cancelled ? SessionEvent::Kind::cancelled
                                                   : SessionEvent::Kind::failed;
  events_.push_back({kind, done_, why, {}});
}

std::string S3gSession::take_output() {
  return std::exchange(output_, {});
}

std::vector<SessionEvent> S3gSession::take_events() {
  return std::exchange(events_, {});
}

Millis S3gSession::deadline() const {
  Millis d = Millis::max();
  if (in_flight_) return reply_deadline_;
  if (!control_.empty()) d = std::min(d, control_not_before_);
  if (quiet_) d = std::min(d, quiet_until_);
  if (printing_phase()) {
    d = std::min({d, next_stats_, next_temps_});
    if (need_room_ || snapshot_) d = std::min(d, next_room_poll_);
    if (toggled_at_) d = std::min(d, *toggled_at_ + config_.pause_confirm);
  } else if (last_poll_) {
    d = std::min(d, *last_poll_ + config_.idle_poll);
  }
  return d;
}

}  // namespace salient::protocol::s3g
