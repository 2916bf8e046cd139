// SailfishFirmware. Times: the driver's clock in microseconds. Motion and heating happen in printer
// seconds, turned into wall time by time_scale / heat_time_scale (0: instant); resets, the packet
// timeout and the cancel's delay are wall time, since they are aimed at the host.
#include "protocol/sim/sailfish_firmware.hpp"

#include <algorithm>
#include <cmath>

#include "protocol/s3g/s3g_codes.hpp"
#include "protocol/s3g/x3g_commands.hpp"

namespace salient::protocol::sim {

using s3g::Action;
using s3g::Query;
using s3g::Reply;
using s3g::ToolCommand;

namespace {

constexpr std::uint8_t kVariantSailfish = 0x80;
constexpr double kMaxWallSeconds = 1e9;  // an absurd duration from a hostile payload stays finite

std::string code(Reply r) {
  return std::string(1, static_cast<char>(r));
}

std::string ok() {
  return code(Reply::ok);
}

std::string hex(std::string_view bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out;
  out.reserve(bytes.size() * 2);
  for (unsigned char b : bytes) out += digits[b >> 4], out += digits[b & 15];
  return out;
}

std::uint8_t u8(std::string_view a, std::size_t at) {
  return s3g::get_u8(a, at);
}

}  // namespace

SailfishFirmware::SailfishFirmware(SailfishConfig config)
    : config_(config), in_(config.baud / 10), out_(config.baud / 10), rng_(config.faults.seed) {
  hotend_ = {config_.ambient, 0, config_.hotend_rate, config_.hotend_cool};
  bed_ = {config_.ambient, 0, config_.bed_rate, config_.bed_cool};
}

double SailfishFirmware::heat_scale() const {
  return config_.heat_time_scale < 0 ? config_.time_scale : config_.heat_time_scale;
}

Micros SailfishFirmware::scaled(double printer_seconds, double scale) const {
  const double s = printer_seconds * scale;
  if (!(s > 0)) return Micros{0};  // NaN too
  return Micros(static_cast<long long>(std::llround(std::min(s, kMaxWallSeconds) * 1e6)));
}

bool SailfishFirmware::chance(double p) {
  return p > 0 && std::bernoulli_distribution(p)(rng_);
}

void SailfishFirmware::receive(std::string_view bytes, Micros now) {
  in_.push(bytes, now);
}

std::string SailfishFirmware::take_output(Micros now) {
  return out_.pop(now);
}

// ---- the link: bytes to packets, packets to replies ----

// noise: one byte of the host's packet changes. Which one is chosen as its start byte arrives
// (k in 0…34, 0 the start byte, 1 the length) and folded onto its payload and CRC once its
// length is known, so that every packet length is hit alike.
std::uint8_t SailfishFirmware::corrupt_incoming(std::uint8_t byte) {
  byte_host_at_ = -1;
  byte_corrupted_ = false;
  if (host_at_ < 0) {
    if (byte != s3g::kStartByte) return byte;  // the host's own stray byte
    host_at_ = 0;
    host_length_ = 0;
    corrupt_at_ = chance(config_.faults.noise) ? std::uniform_int_distribution<int>(0, 34)(rng_) : -1;
  }
  const int at = host_at_++;
  byte_host_at_ = at;
  byte_corrupted_ = at == corrupt_at_;
  if (at == 1) {
    host_length_ = byte;
    if (corrupt_at_ > 1) corrupt_at_ = 2 + (corrupt_at_ - 2) % (host_length_ + 1);
  }
  byte_ends_packet_ = at >= 2 && at == host_length_ + 2;
  if ((at == 1 && (byte == 0 || byte > s3g::kMaxPayload)) || byte_ends_packet_)
    host_at_ = -1;  // the host's packet ends here
  if (at != corrupt_at_) return byte;
  ++stats_.packets_corrupted;
  return static_cast<std::uint8_t>(byte ^ std::uniform_int_distribution<int>(1, 255)(rng_));
}

void SailfishFirmware::feed(std::uint8_t byte, Micros now) {
  if (decoder_.in_packet() && now - packet_started_ >= config_.packet_timeout) {
    decoder_.reset();
    ++stats_.packet_timeouts;
    link_error(Reply::packet_timeout, now);
  }
  byte = corrupt_incoming(byte);
  const bool was_in_packet = decoder_.in_packet();
  s3g::PacketDecoder::Result r = decoder_.feed(byte);
  // Is the packet the decoder reads one the host sent, byte for byte?
  packet_true_ = (was_in_packet ? packet_true_ && byte_host_at_ > 0 : byte_host_at_ == 0) && !byte_corrupted_;
  if (!was_in_packet) {
    if (decoder_.in_packet()) {
      packet_started_ = now;
    } else {
      ++stats_.stray_bytes;
      link_error(Reply::generic_error, now);
    }
    return;
  }
  if (r.error == s3g::PacketDecoder::Error::bad_length) {
    ++stats_.length_errors;
    link_error(Reply::packet_too_big, now);
  } else if (r.error == s3g::PacketDecoder::Error::bad_crc) {
    ++stats_.crc_errors;
    link_error(Reply::crc_mismatch, now);
  } else if (r.payload) {
    if (!packet_true_ || !byte_ends_packet_) ++stats_.false_packets;
    handle_packet(*r.payload, now);
  }
}

// A packet the board could not read: answered, or, as Sailfish 7.7 does, not (Host.cc has the
// replies commented out), and the host waits for its reply timeout.
void SailfishFirmware::link_error(s3g::Reply r, Micros now) {
  if (config_.error_replies) reply(code(r), now);
}

void SailfishFirmware::reply(std::string payload, Micros now) {
  if (chance(config_.faults.drop_reply)) {
    ++stats_.replies_dropped;
    return;
  }
  std::string framed = s3g::frame(payload);
  if (chance(config_.faults.reply_noise)) {
    const auto at = std::uniform_int_distribution<std::size_t>(0, framed.size() - 1)(rng_);
    framed[at] = static_cast<char>(framed[at] ^ std::uniform_int_distribution<int>(1, 255)(rng_));
    ++stats_.replies_corrupted;
  }
  out_.push(framed, now);
}

void SailfishFirmware::handle_packet(const std::string& payload, Micros now) {
  ++stats_.packets_received;
  if (cancel_pending_) {  // Host.cc: the packet after a cancel is answered 89 and not run
    cancel_pending_ = false;
    reply(code(Reply::cancelled), now);
    reset(now);
    return;
  }
  if (state_ == State::heater_shutdown) {
    reply(code(Reply::heater_shutdown), now);
    return;
  }
  reply(answer(payload, now), now);
  if (static_cast<std::uint8_t>(payload[0]) == static_cast<std::uint8_t>(Query::reset)) reset(now);
  run(now);  // at time scale 0 an action runs as it arrives
}

std::string SailfishFirmware::answer(const std::string& payload, Micros now) {
  if (static_cast<std::uint8_t>(payload[0]) & 0x80) return queue_action(payload);
  try {
    return query(payload, now);
  } catch (const std::out_of_range&) {  // a query too short for its fields: a host bug
    ++stats_.unsupported;
    return code(Reply::unsupported);
  }
}

// Host.cc's processCommandPacket: queued whole when it fits, never looked at.
std::string SailfishFirmware::queue_action(const std::string& payload) {
  const bool fits = payload.size() <= config_.ring_bytes - ring_.size();
  // A storm starts only on an action that would be taken, and one that ended takes the next.
  if (fits && storm_left_ == 0 && !storm_ended_ && chance(config_.faults.full_storm))
    storm_left_ = std::uniform_int_distribution<int>(1, 20)(rng_);
  if (!fits || storm_left_ > 0) {
    if (fits) --storm_left_, ++stats_.storm_refusals, storm_ended_ = storm_left_ == 0;
    ++stats_.buffer_full_sent;
    return code(Reply::buffer_full);
  }
  storm_ended_ = false;
  ring_ += payload;
  return ok();
}

std::string SailfishFirmware::query(const std::string& p, Micros now) {
  std::string r = ok();
  std::size_t at = 1;
  switch (static_cast<Query>(p[0])) {
    case Query::version: {
      // Sailfish answers 0 to a host older than 26 (ReplicatorG 0025), so that it says "upgrade".
      const bool old_host = p.size() >= 3 && s3g::get_u16(p, at) <= 25;
      s3g::put_u16(r, old_host ? 0 : config_.firmware_version);
      return r;
    }
    case Query::advanced_version:
      s3g::put_u16(r, config_.firmware_version);
      s3g::put_u16(r, config_.internal_version);
      s3g::put_u8(r, kVariantSailfish);
      s3g::put_u8(r, 0);
      s3g::put_u16(r, 0);
      return r;
    case Query::init:
      return r;
    case Query::buffer_space:
      s3g::put_u32(r, static_cast<std::uint32_t>(config_.ring_bytes - ring_.size()));
      return r;
    case Query::clear_buffer:
      ring_.clear();
      return r;
    case Query::abort:
      ring_.clear();
      stop_motion(now);
      heaters_off();
      if (build_ == Build::running || build_ == Build::paused) build_ = Build::cancelled;
      paused_ = false;
      return r;
    case Query::pause:  // a toggle, and only while building; ok whatever it did
      if (build_ == Build::running || build_ == Build::paused) {
        paused_ = !paused_;
        build_ = paused_ ? Build::paused : Build::running;
      }
      return r;
    case Query::tool_query:
      r = tool_query(p);
      if (static_cast<std::uint8_t>(r[0]) == static_cast<std::uint8_t>(Reply::unsupported))
        ++stats_.unsupported;
      return r;
    case Query::is_finished:
      s3g::put_u8(r, !running_ && ring_.empty() ? 1 : 0);
      return r;
    case Query::reset:
      return r;  // the reset follows the reply
    case Query::position:
      for (std::int32_t v : pos_) s3g::put_i32(r, v);
      s3g::put_u16(r, endstops_);
      return r;
    case Query::extended_stop: {
      const std::uint8_t flags = s3g::get_u8(p, at);
      if (flags & 1) stop_motion(now);
      if (flags & 2) ring_.clear();
      s3g::put_u8(r, 0);
      return r;
    }
    case Query::board_status: {
      // Bit 0: preheating (a heater short of its target); bit 7: heater shutdown never shows
      // here, since that board answers 8B to everything.
      const bool heating = !heater_ready(hotend_) || !heater_ready(bed_);
      s3g::put_u8(r, heating ? 1 : 0);
      return r;
    }
    case Query::build_stats: {
      const Micros t =
          build_ == Build::running || build_ == Build::paused ? now - build_started_ : last_build_time_;
      const long long minutes = t.count() / 60000000;
      s3g::put_u8(r, static_cast<std::uint8_t>(build_));
      s3g::put_u8(r, static_cast<std::uint8_t>(std::min<long long>(minutes / 60, 255)));
      s3g::put_u8(r, static_cast<std::uint8_t>(minutes % 60));
      s3g::put_u32(r, static_cast<std::uint32_t>(line_));
      s3g::put_u32(r, 0);
      return r;
    }
  }
  ++stats_.unsupported;
  return code(Reply::unsupported);
}

std::string SailfishFirmware::tool_query(const std::string& p) const {
  std::size_t at = 1;
  s3g::get_u8(p, at);  // the tool: one extruder here
  const auto command = static_cast<ToolCommand>(s3g::get_u8(p, at));
  std::string r = ok();
  auto degrees = [&](double t) { s3g::put_i16(r, static_cast<std::int16_t>(std::lround(t))); };
  switch (command) {
    case ToolCommand::get_temperature:
      degrees(hotend_.temperature);
      return r;
    case ToolCommand::target_temperature:
      degrees(hotend_.target);
      return r;
    case ToolCommand::platform_temperature:
      degrees(bed_.temperature);
      return r;
    case ToolCommand::platform_target:
      degrees(bed_.target);
      return r;
    case ToolCommand::is_ready:
      s3g::put_u8(r, heater_ready(hotend_) ? 1 : 0);
      return r;
    case ToolCommand::platform_ready:
      s3g::put_u8(r, heater_ready(bed_) ? 1 : 0);
      return r;
    case ToolCommand::status:
      s3g::put_u8(r, heater_ready(hotend_) ? 1 : 0);
      return r;
    default:
      return code(Reply::unsupported);
  }
}

// ---- the command ring: actions run one after another ----

void SailfishFirmware::run(Micros now) {
  while (state_ == State::ready) {
    if (running_ && !finish_current(now)) return;
    if (paused_ || ring_.empty()) return;
    std::optional<std::size_t> n;
    try {
      n = s3g::action_length(ring_);
    } catch (const s3g::X3gError&) {
      return;  // not an action: it stays at the head for ever, as on the board
    }
    if (!n) return;  // not all of it is in yet
    const std::string action = ring_.substr(0, *n);
    ring_.erase(0, *n);
    start(action, now);
    after_started(now);
  }
}

bool SailfishFirmware::finish_current(Micros now) {
  if (wait_ != Wait::none) {
    const Heater& h = wait_ == Wait::hotend ? hotend_ : bed_;
    if (!heater_ready(h) && now < wait_deadline_) return false;
  } else if (now < until_) {
    return false;
  }
  running_ = false;
  wait_ = Wait::none;
  return true;
}

void SailfishFirmware::start(const std::string& a, Micros now) {
  ++stats_.executed;
  ++line_;
  executed_.push_back(hex(a));
  running_ = true;
  until_ = now;
  wait_ = Wait::none;
  std::size_t at = 1;
  switch (static_cast<Action>(a[0])) {
    case Action::home_min:
    case Action::home_max: {
      const std::uint8_t axes = u8(a, 1);
      until_ = now + home_time(a);
      const int side = a[0] == static_cast<char>(Action::home_max) ? 1 : 0;
      for (int i = 0; i < 5; ++i) {
        if (!(axes & (1 << i))) continue;
        pos_[i] = config_.home_steps[i];
        homed_ |= static_cast<std::uint8_t>(1 << i);
        endstops_ = static_cast<std::uint16_t>((endstops_ & ~(3u << (2 * i))) | (1u << (2 * i + side)));
      }
      break;
    }
    case Action::delay:
      until_ = now + scaled(s3g::get_u32(a, at) / 1000.0, config_.time_scale);
      break;
    case Action::wait_for_tool:
    case Action::wait_for_platform: {
      at = 4;  // tool, then the poll interval (ms), which a board need not honour
      const std::uint16_t timeout_s = s3g::get_u16(a, at);
      wait_ = a[0] == static_cast<char>(Action::wait_for_tool) ? Wait::hotend : Wait::bed;
      wait_deadline_ = timeout_s == 0 ? Micros::max() : now + scaled(timeout_s, heat_scale());
      break;
    }
    case Action::tool_action: {
      const auto command = static_cast<ToolCommand>(u8(a, 2));
      at = 4;
      if (command == ToolCommand::set_temperature && a.size() >= 6)
        hotend_.target = std::max<std::int16_t>(0, s3g::get_i16(a, at));
      else if (command == ToolCommand::set_platform_temperature && a.size() >= 6)
        bed_.target = std::max<std::int16_t>(0, s3g::get_i16(a, at));
      else if ((command == ToolCommand::fan || command == ToolCommand::extra_output) && a.size() >= 5)
        fan_ = u8(a, 4) & 1;
      break;
    }
    case Action::queue_point_ext:
    case Action::queue_point_new:
    case Action::queue_point:
      until_ = now + move(a);
      break;
    case Action::set_position:
      for (auto& p : pos_) p = s3g::get_i32(a, at);
      break;
    case Action::recall_home: {
      const std::uint8_t axes = u8(a, 1);
      for (int i = 0; i < 5; ++i)
        if (axes & (1 << i)) pos_[i] = config_.home_steps[i];
      break;
    }
    case Action::build_percent:
      percent_ = u8(a, 1);
      break;
    case Action::build_start:
      build_ = Build::running;
      build_started_ = now;
      percent_ = 0;
      paused_ = false;
      break;
    case Action::build_end:
      build_ = Build::finished;
      last_build_time_ = now - build_started_;
      heaters_off();
      fan_ = false;
      break;
    default:
      break;  // the LED, the beeper, messages, a button (pressed at once), …: no time, no state
  }
}

// 155: distance / (feed / 64), or the DDA rate (steps per second) over the longest axis when it
// carries no distance; 139: microseconds per step; 142: its own duration. Sets the target.
Micros SailfishFirmware::move(const std::string& a) {
  std::size_t at = 1;
  std::array<std::int32_t, 5> v{};
  for (auto& x : v) x = s3g::get_i32(a, at);
  const auto id = static_cast<Action>(a[0]);
  const std::uint32_t rate = s3g::get_u32(a, at);
  std::uint8_t relative = 0;
  if (id != Action::queue_point_ext) relative = s3g::get_u8(a, at);
  double longest = 0;
  for (int i = 0; i < 5; ++i) {
    const double target = (relative & (1 << i)) ? double(pos_[i]) + v[i] : double(v[i]);
    const double steps = std::abs(target - pos_[i]);
    if (steps > 0) endstops_ = static_cast<std::uint16_t>(endstops_ & ~(3u << (2 * i)));
    longest = std::max(longest, steps);
    pos_[i] = static_cast<std::int32_t>(std::clamp(target, -2147483648.0, 2147483647.0));
  }
  double seconds = 0;
  if (id == Action::queue_point_ext) {
    seconds = longest * rate / 1e6;
  } else if (id == Action::queue_point_new) {
    seconds = rate / 1e6;
  } else {
    const double distance = s3g::get_f32(a, at);
    const double mm_per_s = s3g::get_u16(a, at) / 64.0;
    if (distance > 0 && mm_per_s > 0)
      seconds = distance / mm_per_s;
    else if (rate > 0)
      seconds = longest / rate;
  }
  return scaled(seconds, config_.time_scale);
}

// Homing runs at its step rate over the distance to the endstop: all the travel from an unknown
// position. Capped by its timeout.
Micros SailfishFirmware::home_time(const std::string& a) const {
  std::size_t at = 1;
  const std::uint8_t axes = s3g::get_u8(a, at);
  const std::uint32_t us_per_step = s3g::get_u32(a, at);
  const std::uint16_t timeout_s = s3g::get_u16(a, at);
  double seconds = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(axes & (1 << i))) continue;
    const double steps = (homed_ & (1 << i)) ? std::abs(double(pos_[i]) - config_.home_steps[i])
                                             : config_.travel_mm[i] * config_.steps_per_mm[i];
    seconds = std::max(seconds, steps * us_per_step / 1e6);
  }
  if (timeout_s > 0) seconds = std::min<double>(seconds, timeout_s);
  return scaled(seconds, config_.time_scale);
}

// Faults at a known moment, as action N starts.
void SailfishFirmware::after_started(Micros now) {
  const SailfishFaults& f = config_.faults;
  const long long n = stats_.executed;
  if (n == f.reset_at) reset(now);
  if (n == f.cancel_at) cancel(now);
  if (n == f.heater_fault_at) {
    state_ = State::heater_shutdown;
    heaters_off();
    stop_motion(now);
  }
  if (n == f.silent_after) state_ = State::silent;
}

void SailfishFirmware::stop_motion(Micros now) {
  running_ = false;
  wait_ = Wait::none;
  until_ = now;
}

void SailfishFirmware::heaters_off() {
  hotend_.target = 0;
  bed_.target = 0;
}

void SailfishFirmware::reset(Micros now) {
  ++stats_.resets;
  state_ = State::resetting;
  deaf_until_ = now + config_.reset_for;
  ring_.clear();
  stop_motion(now);
  heaters_off();
  fan_ = false;
  paused_ = false;
  build_ = Build::none;
  line_ = 0;
  pos_ = {};
  endstops_ = 0;
  homed_ = 0;
  cancel_pending_ = false;
  cancel_reset_at_ = Micros::max();
  storm_left_ = 0;
  storm_ended_ = false;
  decoder_.reset();
  host_at_ = -1;
  in_.clear();
}

// The LCD's cancel (Host.cc stopBuild): the build stops now; the next packet learns it (89), and
// the board resets after that, or after cancel_reset_after if no packet comes.
void SailfishFirmware::cancel(Micros now) {
  build_ = Build::cancelled;
  ring_.clear();
  stop_motion(now);
  heaters_off();
  paused_ = false;
  cancel_pending_ = true;
  cancel_reset_at_ = now + config_.cancel_reset_after;
}

// ---- heaters ----

void SailfishFirmware::update_heaters(Micros now) {
  if (now < heaters_at_) return;  // a driver's clock never goes back; if it did, time stands still
  const double scale = heat_scale();
  const double dt = static_cast<double>((now - heaters_at_).count()) / 1e6;
  heaters_at_ = now;
  for (Heater* h : {&hotend_, &bed_}) {
    const double goal = h->target > 0 ? h->target : config_.ambient;
    if (scale <= 0) {
      h->temperature = goal;
      continue;
    }
    const double printer_dt = dt / scale;
    if (h->temperature < goal)
      h->temperature = std::min(goal, h->temperature + h->rate * printer_dt);
    else
      h->temperature = std::max(goal, h->temperature - h->cool * printer_dt);
  }
}

bool SailfishFirmware::heater_ready(const Heater& h) const {
  return h.target <= 0 || std::abs(h.temperature - h.target) <= config_.ready_band;
}

Micros SailfishFirmware::heater_ready_at(const Heater& h, Micros now) const {
  if (heater_ready(h)) return now;
  const double gap = std::abs(h.temperature - h.target) - config_.ready_band;
  const double rate = h.temperature < h.target ? h.rate : h.cool;
  return now + scaled(gap / rate, heat_scale()) + Micros{1};
}

// ---- the driver's entry points ----

void SailfishFirmware::advance(Micros now) {
  update_heaters(now);
  if (state_ == State::resetting && now >= deaf_until_) state_ = State::ready;
  if (cancel_pending_ && now >= cancel_reset_at_) reset(now);
  run(now);
  for (unsigned char b : in_.pop(now)) {
    if (state_ == State::resetting || state_ == State::silent)
      ++stats_.bytes_ignored;
    else
      feed(b, now);
  }
  if (state_ != State::resetting && state_ != State::silent && decoder_.in_packet() &&
      now - packet_started_ >= config_.packet_timeout) {
    decoder_.reset();
    ++stats_.packet_timeouts;
    link_error(Reply::packet_timeout, now);
  }
  run(now);
}

// The wire's bytes are taken when the last one sent so far has arrived, not one wakeup a byte:
// a packet is read whole (3 ms at 115200 baud), and a longer stream at least every 5 ms, which
// keeps the 200 ms packet timeout true to a few ms.
Micros SailfishFirmware::next_wakeup() const {
  constexpr Micros kBatch{5000};
  Micros t = out_.last_arrival();
  if (!in_.empty()) t = std::min({t, in_.last_arrival(), in_.next_arrival() + kBatch});
  if (state_ == State::resetting) return std::min(t, deaf_until_);
  if (state_ == State::silent) return t;
  if (decoder_.in_packet()) t = std::min(t, packet_started_ + config_.packet_timeout);
  if (cancel_pending_) t = std::min(t, cancel_reset_at_);
  if (state_ == State::ready && running_) {
    if (wait_ == Wait::none)
      t = std::min(t, until_);
    else
      t = std::min({t, wait_deadline_, heater_ready_at(wait_ == Wait::hotend ? hotend_ : bed_, heaters_at_)});
  }
  return t;
}

}  // namespace salient::protocol::sim
