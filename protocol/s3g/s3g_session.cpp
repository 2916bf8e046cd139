#include "protocol/s3g/s3g_session.hpp"

#include <algorithm>
#include <cmath>
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
void S3gSession::send(Packet p, Millis now) {
  output_ += frame(p.payload);
  in_flight_packet_ = std::move(p);
  in_flight_ = true;
  sent_at_ = now;
  sample_reply_ = in_flight_packet_->tries == 0;
  reply_deadline_ = now + reply_wait();
  decoder_.reset();
  got_bytes_ = false;
}

Millis S3gSession::reply_wait() const {
  if (!have_rtt_) return config_.reply_timeout;
  const auto rto = Millis(static_cast<long long>(srtt_ms_ + 4 * rttvar_ms_ + 1));
  return std::clamp(rto, std::min(config_.min_reply_timeout, config_.reply_timeout), config_.reply_timeout);
}

void S3gSession::sample_reply_time(Millis sample) {
  const double r = static_cast<double>(sample.count());
  if (!have_rtt_) {
    srtt_ms_ = r, rttvar_ms_ = r / 2, have_rtt_ = true;
  } else {
    rttvar_ms_ = 0.75 * rttvar_ms_ + 0.25 * std::abs(srtt_ms_ - r);
    srtt_ms_ = 0.875 * srtt_ms_ + 0.125 * r;
  }
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
    // All queued: build stats tell when the board has started the last; ask soon, the line is idle.
    next_stats_ = std::min(next_stats_, now + config_.buffer_poll);
    return std::nullopt;
  }
  return current_;
}

void S3gSession::on_receive(std::string_view bytes, Millis now) {
  last_heard_ += host_gap_.looked(now);
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
      if (sample_reply_) sample_reply_time(now - sent_at_);
      on_reply(*r.payload, now);
      if (i + 1 < bytes.size()) quiet_ = true, quiet_until_ = now + config_.quiet_gap;  // more than one reply
    } else if (r.error != PacketDecoder::Error::none) {
      in_flight_ = false;
      on_garbled(now, r.error == PacketDecoder::Error::bad_crc ? "bad CRC" : "bad length");
    }
  }
  // A reply comes as one burst: bytes that made none by byte_timeout after the last were noise.
  if (in_flight_) got_bytes_ = true;
  if (in_flight_) reply_deadline_ = std::min(reply_deadline_, now + config_.byte_timeout);
  if (in_flight_ && decoder_.in_packet()) reply_deadline_ = now + config_.byte_timeout;
  pump(now);
}

void S3gSession::on_tick(Millis now) {
  last_heard_ += host_gap_.looked(now);  // silence counts only while the host was there to hear
  if (in_flight_ && now >= reply_deadline_) {
    in_flight_ = false;
    ++timeouts_;
    on_garbled(now, got_bytes_ ? "bytes that made no reply" : "no reply");
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
  Packet p = std::move(*in_flight_packet_);
  in_flight_packet_.reset();
  quiet_ = true, quiet_until_ = now + config_.quiet_gap;
  decoder_.reset();
  if (++garbled_run_ > config_.max_garbled && std::string_view(why) != "no reply") {
    garbled_run_ = 0;
    const std::string text = "no intelligible reply in " + std::to_string(config_.max_garbled) +
                             " packets (last: " + why + "): is it an s3g board, at the right baud rate?";
    if (printing_phase() || ending_) {
      fail(text);
      return;
    }
    events_.push_back({SessionEvent::Kind::error, 0, text, {}});
  }
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
