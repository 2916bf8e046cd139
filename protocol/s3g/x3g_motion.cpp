// The translator's motion: G0/G1 (gpx.c calculate_target_position, queue_ext_point, queue_absolute_point,
// update_current_position), homing, forgetting positions, and tool changes.
#include <algorithm>
#include <array>
#include <cmath>

#include "protocol/s3g/x3g_translator_state.hpp"

namespace salient::protocol::s3g::detail {

// gpx.c calculate_target_position + queue_ext_point + update_current_position.
void Translator::move() {
  const auto& off = offsets_[offset_];
  Vec5 delta;
  bool relative = false;
  const auto axis = [&](unsigned bit, double word, double offset, double cur, double& target, double& d) {
    target = cur;
    if (!(w_.flag & bit)) return;
    if (relative_) {
      d = word;
      target += d;
      relative = relative || (known_ & bit);
    } else {
      target = word + offset;
      d = target - cur;
    }
  };
  axis(kX, w_.x, off[0], current_.x, target_.x, delta.x);
  axis(kY, w_.y, off[1], current_.y, target_.y, delta.y);
  axis(kZ, w_.z, off[2], current_.z, target_.z, delta.z);
  const auto extruder = [&](unsigned bit, double word, double cur, double& target, double& d) {
    target = cur;
    if (!(w_.flag & bit)) return;
    if (relative_ || extruder_relative_) {
      d = word;
      target += word;
    } else {
      target = word;
      d = target - cur;
    }
  };
  extruder(kA, w_.a, current_.a, target_.a, delta.a);
  extruder(kB, w_.b, current_.b, target_.b, delta.b);
  if (w_.flag & kF) feedrate_ = w_.f;

  queue_point(delta, relative);
  current_ = target_;
  if (!relative_) known_ |= w_.flag & mask_;
}

void Translator::queue_point(const Vec5& delta, bool relative) {
  const unsigned flag = w_.flag;
  const unsigned named = flag & mask_;
  const unsigned still_unknown = ~(known_ | named) & mask_;
  if ((known_ & named) != named && !relative && !still_unknown) return queue_absolute_point();

  Vec5 d = delta;
  if (!still_unknown && !relative) {
    d = {};
    if (flag & kX) d.x = target_.x - current_.x;
    if (flag & kY) d.y = target_.y - current_.y;
    if (flag & kZ) d.z = target_.z - current_.z;
    if (flag & kA) d.a = (target_.a - current_.a) * extrusion_factor_[0] / 100;
    if (flag & kB) d.b = (target_.b - current_.b) * extrusion_factor_[1] / 100;
  }
  Vec5 steps;  // |Δ| in steps, per named axis
  if (flag & kX) steps.x = std::round(std::fabs(d.x) * m_.x.steps_per_mm);
  if (flag & kY) steps.y = std::round(std::fabs(d.y) * m_.y.steps_per_mm);
  if (flag & kZ) steps.z = std::round(std::fabs(d.z) * m_.z.steps_per_mm);
  if (flag & kA) steps.a = std::round(std::fabs(d.a) * m_.a.steps_per_mm);
  if (flag & kB) steps.b = std::round(std::fabs(d.b) * m_.b.steps_per_mm);
  if (!(magnitude(flag, steps) > 0)) return;  // less than a step on every axis: nothing to send

  double distance = magnitude(flag & kXYZ, d);
  Vec5 point = relative ? delta : target_;
  if (still_unknown & kX) point.x = 0;
  if (still_unknown & kY) point.y = 0;
  if (still_unknown & kZ) point.z = 0;
  point.a = -d.a;
  point.b = -d.b;
  const Vec5 abs{std::fabs(d.x), std::fabs(d.y), std::fabs(d.z), std::fabs(d.a), std::fabs(d.b)};

  // gpx.c get_safe_feedrate
  double feedrate = feedrate_ * (static_cast<double>(speed_factor_) / 100);
  if (feedrate == 0.0)
    feedrate = std::max(
        {m_.x.max_feedrate, m_.y.max_feedrate, m_.z.max_feedrate, m_.a.max_feedrate, m_.b.max_feedrate});
  const double length = magnitude(flag & kXYZ, abs);
  const auto limit = [&](unsigned bit, double axis_delta, double max) {
    if ((flag & bit) && feedrate * axis_delta / length > max) feedrate = max * length / axis_delta;
  };
  limit(kX, abs.x, m_.x.max_feedrate);
  limit(kY, abs.y, m_.y.max_feedrate);
  limit(kZ, abs.z, m_.z.max_feedrate);
  if (length == 0) {
    if ((flag & kA) && feedrate > m_.a.max_feedrate) feedrate = m_.a.max_feedrate;
    if ((flag & kB) && feedrate > m_.b.max_feedrate) feedrate = m_.b.max_feedrate;
  } else {
    limit(kA, abs.a, m_.a.max_feedrate);
    limit(kB, abs.b, m_.b.max_feedrate);
  }

  double minutes = distance / feedrate;
  if (minutes == 0) {
    distance = 0;
    if (flag & kA) distance = abs.a;
    if ((flag & kB) && distance < abs.b) distance = abs.b;
    minutes = distance / feedrate;
  }
  const double mm_per_s = feedrate / 60.0;
  const auto s = to_steps(point, true);
  const double usec = static_cast<double>(60000000.0L * minutes);
  const double dda_interval = usec / largest_axis(flag, steps);
  const double dda_rate = static_cast<double>(1000000.0L / dda_interval);
  const auto mask = static_cast<std::uint8_t>(relative ? kAxes : (still_unknown | kA | kB));
  emit(actions::queue_point(s, to_u32(dda_rate), mask, static_cast<float>(distance),
                            static_cast<std::uint16_t>(to_u32(mm_per_s * 64.0))));
}

// gpx.c queue_absolute_point: 139, at the slowest of the named axes' DDA for the feed rate.
void Translator::queue_absolute_point() {
  std::int64_t dda = std::min({to_i32(60 * 1000000.0 / (m_.x.max_feedrate * m_.x.steps_per_mm)),
                               to_i32(60 * 1000000.0 / (m_.y.max_feedrate * m_.y.steps_per_mm)),
                               to_i32(60 * 1000000.0 / (m_.z.max_feedrate * m_.z.steps_per_mm))});
  auto s = to_steps(target_, true);
  const double feedrate = feedrate_ * (static_cast<double>(speed_factor_) / 100);
  if (feedrate > 0) {
    const std::array<double, 5> spm{m_.x.steps_per_mm, m_.y.steps_per_mm, m_.z.steps_per_mm,
                                    m_.a.steps_per_mm, m_.b.steps_per_mm};
    for (std::size_t i = 0; i < 5; ++i)
      if (s[i]) dda = std::max(dda, to_i64(60.0 * 1000000.0 / (spm[i] * feedrate)));
  }
  if (dda <= 0) dda = 200;
  for (std::size_t i = 3; i < 5; ++i) s[i] = static_cast<std::int32_t>(0u - static_cast<std::uint32_t>(s[i]));
  emit(actions::queue_point_absolute(s, static_cast<std::uint32_t>(dda)));  // (int)long: the low 32 bits
  known_ = mask_;
}

// gpx.c home_axes: µs per step on the axis with the most steps per mm, at the slowest home feed.
void Translator::home(unsigned axes, bool to_max) {
  double feedrate = 0.0;
  if (w_.flag & kF) {
    feedrate = feedrate_;
  } else {
    if (w_.flag & kX) feedrate = m_.x.home_feedrate;
    if ((w_.flag & kY) && feedrate < m_.y.home_feedrate) feedrate = m_.y.home_feedrate;
    if ((w_.flag & kZ) && feedrate < m_.z.home_feedrate) feedrate = m_.z.home_feedrate;
  }
  double longest = 0.0, acc = 0.0;
  const std::array<const Axis*, 3> xyz{&m_.x, &m_.y, &m_.z};
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(axes & (1u << i))) continue;
    feedrate = std::min(feedrate, xyz[i]->home_feedrate);
    longest = std::max(longest, xyz[i]->steps_per_mm);
    acc += 1.0;
  }
  const double microseconds = std::sqrt(acc) / feedrate * 60000000.0;
  const std::uint32_t step_delay = to_u32(std::round(microseconds / longest));
  emit(actions::home(to_max, static_cast<std::uint8_t>(axes), step_delay,
                     static_cast<std::uint16_t>(m_.timeout)));
}

void Translator::set_unknown(unsigned flag) {
  known_ &= ~(flag & mask_);
  if (flag & kX) current_.x = 0;
  if (flag & kY) current_.y = 0;
  if (flag & kZ) current_.z = 0;
  if (flag & kA) current_.a = 0;
  if (flag & kB) current_.b = 0;
  excess_a_ = excess_b_ = 0;
}

// gpx.c do_tool_change: standby/active temperatures from G10, 134, and a move to where the head
// is (139) so that the firmware applies the tool offset on an unaccelerated move.
void Translator::tool_change() {
  if (standby_[tool_] && standby_[tool_] != nozzle_[tool_]) {
    emit(actions::nozzle_temperature(static_cast<std::uint8_t>(tool_),
                                     static_cast<std::uint16_t>(standby_[tool_])));
    nozzle_[tool_] = standby_[tool_];
  }
  const unsigned t = target_tool_;
  if (active_[t] && active_[t] != nozzle_[t]) {
    emit(actions::nozzle_temperature(static_cast<std::uint8_t>(t), static_cast<std::uint16_t>(active_[t])));
    nozzle_[t] = active_[t];
  }
  if (offset_ == tool_ + 1) offset_ = t + 1;
  emit(actions::change_tool(static_cast<std::uint8_t>(t)));
  if ((known_ & mask_) == mask_) {
    target_ = current_;
    queue_absolute_point();
  }
  tool_ = t;
}

}  // namespace salient::protocol::s3g::detail
