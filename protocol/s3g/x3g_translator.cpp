#include "protocol/s3g/x3g_translator.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "protocol/s3g/gcode_words.hpp"
#include "protocol/s3g/x3g_actions.hpp"

namespace salient::protocol::s3g {
namespace {

constexpr unsigned kX = word::X, kY = word::Y, kZ = word::Z, kA = word::A, kB = word::B, kXYZ = word::XYZ,
                   kAxes = word::AXES, kE = word::E, kF = word::F, kP = word::P, kR = word::R, kS = word::S,
                   kG = word::G, kM = word::M, kT = word::T;
constexpr unsigned kNozzleMax = 280;      // °C: gpx clamps M104/M109 here
constexpr unsigned kMaxTimeout = 0xFFFF;  // s: the waits' default timeout

// gpx's casts as gcc compiles them on x86-64: a double out of range becomes INT32_MIN for (int)
// and 0 for (unsigned) (cvttsd2si), instead of undefined behaviour.
std::int32_t to_i32(double v) {
  if (!(v >= -2147483648.0 && v < 2147483648.0)) return INT32_MIN;
  return static_cast<std::int32_t>(v);
}
std::uint32_t to_u32(double v) {
  if (!(v > -9.2233720368547758e18 && v < 9.2233720368547758e18)) return 0;
  return static_cast<std::uint32_t>(static_cast<std::int64_t>(v));
}
std::int64_t to_i64(double v) {
  if (!(v > -9.2233720368547758e18 && v < 9.2233720368547758e18)) return INT64_MIN;
  return static_cast<std::int64_t>(v);
}

// "M104 without S": built by appending (GCC 12 warns falsely on "M" + std::to_string(n)).
std::string code(char letter, long n, std::string_view rest) {
  std::string s(1, letter);
  s.append(std::to_string(n)).append(rest);
  return s;
}

struct Vec5 {
  double x = 0, y = 0, z = 0, a = 0, b = 0;
};

double magnitude(unsigned flag, const Vec5& v) {
  double acc = 0.0;
  if (flag & kX) acc = v.x * v.x;
  if (flag & kY) acc += v.y * v.y;
  if (flag & kZ) acc += v.z * v.z;
  if (flag & kA) acc += v.a * v.a;
  if (flag & kB) acc += v.b * v.b;
  return std::sqrt(acc);
}

double largest_axis(unsigned flag, const Vec5& v) {
  double r = 0.0;
  if (flag & kX) r = std::fabs(v.x);
  if (flag & kY) r = std::max(r, std::fabs(v.y));
  if (flag & kZ) r = std::max(r, std::fabs(v.z));
  if (flag & kA) r = std::max(r, std::fabs(v.a));
  if (flag & kB) r = std::max(r, std::fabs(v.b));
  return r;
}

// Host queries gpx writes into a file anyway: skipped (see the header).
bool is_query(int m) {
  switch (m) {
    case 1:
    case 20:
    case 21:
    case 23:
    case 24:
    case 25:
    case 27:
    case 28:
    case 29:
    case 105:
    case 114:
    case 115:
      return true;
    default:
      return false;
  }
}

class Translator {
 public:
  Translator(const Machine& machine, const TranslateOptions& options, Translation& out)
      : m_(machine), opt_(options), out_(out) {
    feedrate_ = std::max({m_.x.home_feedrate, m_.y.home_feedrate, m_.z.home_feedrate});
    known_ = m_.extruder_count == 1 ? kA : (kA | kB);
    mask_ = m_.extruder_count == 1 ? (kXYZ | kA) : kAxes;
  }

  // False once M2 has ended the program: gpx reads no further.
  bool command(const Program::Command& c, std::size_t index) {
    index_ = index;
    cmd_ = &c;
    w_ = parse_gcode_words(line_of(c));
    if (w_.flag & kT) {
      if (static_cast<unsigned>(w_.t) < m_.extruder_count) target_tool_ = static_cast<unsigned>(w_.t);
    }
    if (w_.flag & kE) {  // E is A or B, by the current tool
      if (tool_ == 0) {
        w_.flag |= kA, w_.a = w_.e;
      } else {
        w_.flag |= kB, w_.b = w_.e;
      }
    }
    if (w_.flag & kG) return g_code(), true;
    if (w_.flag & kM) return m_code();
    if (w_.flag & (kAxes | kF)) {
      if (!(w_.flag & word::COMMENT)) move();  // gpx ignores "X5 ; note"
      return true;
    }
    if (w_.flag & kT) {
      if (target_tool_ != tool_) tool_change();
      return true;
    }
    skip("no G, M or T word");
    return true;
  }

  void finish() {
    if (state_ == State::ended) return;
    state_ = State::ended;
    if (opt_.build_end) {
      emit(actions::build_percent(100));
      emit(actions::build_end());
    }
  }

 private:
  enum class State { ready, running, ended };

  // The command's whole line when the file is at hand (gpx reads comments), else its text.
  std::string_view line_of(const Program::Command& c) const {
    const std::string_view file = opt_.source;
    if (c.offset >= file.size()) return c.text;
    const std::size_t end = file.find('\n', c.offset);
    return file.substr(c.offset, end == std::string_view::npos ? std::string_view::npos : end - c.offset);
  }

  void emit(std::string payload) {
    out_.program.actions.push_back(std::move(payload));
    out_.program.source.push_back(index_);
  }
  void skip(std::string reason) { out_.skipped.push_back({cmd_->line, cmd_->text, std::move(reason)}); }

  std::array<std::int32_t, 5> to_steps(const Vec5& mm, bool carry) {
    std::array<std::int32_t, 5> s{};
    s[0] = to_i32(std::round(mm.x * m_.x.steps_per_mm));
    s[1] = to_i32(std::round(mm.y * m_.y.steps_per_mm));
    s[2] = to_i32(std::round(mm.z * m_.z.steps_per_mm));
    if (carry) {
      double v = mm.a * m_.a.steps_per_mm + excess_a_;
      double r = std::round(v);
      excess_a_ = v - r;
      s[3] = to_i32(r);
      v = mm.b * m_.b.steps_per_mm + excess_b_;
      r = std::round(v);
      excess_b_ = v - r;
      s[4] = to_i32(r);
    } else {
      s[3] = to_i32(std::round(mm.a * m_.a.steps_per_mm));
      s[4] = to_i32(std::round(mm.b * m_.b.steps_per_mm));
    }
    return s;
  }

  void g_code();
  bool m_code();
  bool m_temperature();
  bool m_build();
  void move();
  void queue_point(const Vec5& delta, bool relative);
  void queue_absolute_point();
  void home(unsigned axes, bool to_max);
  void set_unknown(unsigned flag);
  void tool_change();
  void wait_for_bed(bool set_first);
  void display_message();
  void start_build(unsigned percent);
  void end_build();

  const Machine& m_;
  const TranslateOptions& opt_;
  Translation& out_;
  std::size_t index_ = 0;
  const Program::Command* cmd_ = nullptr;
  GcodeWords w_;

  Vec5 current_, target_;
  unsigned known_ = 0, mask_ = 0;
  double excess_a_ = 0, excess_b_ = 0;
  double feedrate_ = 0;  // mm/min
  unsigned speed_factor_ = 100;
  std::array<unsigned, 2> extrusion_factor_{100, 100};
  bool relative_ = false, extruder_relative_ = false;
  unsigned tool_ = 0, target_tool_ = 0;
  std::array<unsigned, 2> nozzle_{}, bed_{}, standby_{}, active_{};
  std::array<std::array<double, 3>, 7> offsets_{};  // G10 P1…P6, [0] the machine's
  unsigned offset_ = 0;
  unsigned percent_ = 0;
  State state_ = State::ready;
};

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

void Translator::start_build(unsigned percent) {
  state_ = State::running;
  if (opt_.build_start) emit(actions::build_start(opt_.build_name));
  percent_ = percent;
  emit(actions::build_percent(static_cast<std::uint8_t>(percent)));
  emit(actions::change_tool(static_cast<std::uint8_t>(tool_)));
}

void Translator::end_build() {
  state_ = State::ended;
  percent_ = 100;
  emit(actions::build_percent(100));
}

void Translator::g_code() {
  switch (w_.g) {
    case 0:
    case 1:
      return move();
    case 4:
      if (w_.flag & kP) return emit(actions::delay(to_u32(w_.p)));
      return skip("G4 without P (milliseconds)");
    case 10: {
      if (!((w_.flag & kP) && w_.p >= 1.0 && w_.p <= 6.0)) return skip("G10 without P1…P6");
      const auto i = static_cast<std::size_t>(w_.p);
      if (w_.flag & kX) offsets_[i][0] = w_.x;
      if (w_.flag & kY) offsets_[i][1] = w_.y;
      if (w_.flag & kZ) offsets_[i][2] = w_.z;
      if (i <= 2 && (w_.flag & kR)) standby_[i - 1] = std::min(to_u32(w_.r), kNozzleMax);
      if (i <= 2 && (w_.flag & kS)) active_[i - 1] = std::min(to_u32(w_.s), kNozzleMax);
      return;
    }
    case 15:
    case 21:
    case 71:
      return;
    case 28: {
      if ((w_.flag & mask_) == 0) w_.flag |= kXYZ;  // none means all
      if (w_.flag & kF) feedrate_ = w_.f;
      unsigned to_max = 0, to_min = 0;
      const std::array<const Axis*, 3> xyz{&m_.x, &m_.y, &m_.z};
      for (unsigned i = 0; i < 3; ++i)
        if (w_.flag & (1u << i)) (xyz[i]->endstop_max ? to_max : to_min) |= 1u << i;
      if (m_.x.endstop_max) {  // X and Y before Z
        if (to_max) home(to_max, true);
        if (to_min) home(to_min, false);
      } else {
        if (to_min) home(to_min, false);
        if (to_max) home(to_max, true);
      }
      return set_unknown(w_.flag);
    }
    case 53:
    case 54:
    case 55:
    case 56:
    case 57:
    case 58:
    case 59:
      offset_ = static_cast<unsigned>(w_.g - 53);
      return;
    case 90:
      relative_ = false;
      return;
    case 91:
      relative_ = true;
      return;
    case 92:
      if (w_.flag & kX) current_.x = w_.x;
      if (w_.flag & kY) current_.y = w_.y;
      if (w_.flag & kZ) current_.z = w_.z;
      if (w_.flag & kA) current_.a = w_.a;
      if (w_.flag & kB) current_.b = w_.b;
      emit(actions::set_position(to_steps(current_, false)));
      known_ |= w_.flag & mask_;
      return;
    case 130: {
      const std::array<double, 5> v{w_.x, w_.y, w_.z, w_.a, w_.b};
      for (unsigned i = 0; i < 5; ++i)
        if (w_.flag & (1u << i))
          emit(actions::set_pot(static_cast<std::uint8_t>(i),
                                static_cast<std::uint8_t>(v[i] < 0     ? 0
                                                          : v[i] > 255 ? 255
                                                                       : to_u32(v[i]))));
      return;
    }
    case 161:
    case 162:
      if (w_.flag & kF) feedrate_ = w_.f;
      home(w_.flag & kXYZ, w_.g == 162);
      return set_unknown(w_.flag);
    default:
      return skip(code('G', w_.g, " is not an s3g command (gpx skips it too)"));
  }
}

// M104 M109 M140 M190 M133 M134 M6 M116: set and wait for temperatures.
bool Translator::m_temperature() {
  const auto timeout =
      static_cast<std::uint16_t>((w_.flag & kP) ? static_cast<unsigned>(to_i32(w_.p)) : kMaxTimeout);
  const auto tool = [](unsigned t) { return static_cast<std::uint8_t>(t); };
  switch (w_.m) {
    case 104:
    case 109: {
      if (!(w_.flag & kS)) return skip(code('M', w_.m, " without S (temperature)")), true;
      unsigned c = std::min(to_u32(w_.s), kNozzleMax);
      if (c && active_[target_tool_]) c = active_[target_tool_];
      emit(actions::nozzle_temperature(tool(target_tool_), static_cast<std::uint16_t>(c)));
      nozzle_[target_tool_] = c;
      if (w_.m == 109 && c > 0) emit(actions::wait_for_tool(tool(target_tool_), 100, timeout));
      return true;
    }
    case 133:
      if (nozzle_[target_tool_] > 0) emit(actions::wait_for_tool(tool(target_tool_), 100, timeout));
      return true;
    case 140:
    case 134:
    case 190: {
      if (!m_.a.heats_bed && !m_.b.heats_bed) return skip("this machine has no heated bed"), true;
      unsigned t = m_.a.heats_bed ? 0 : 1;
      if (w_.flag & kT) t = target_tool_;
      const bool heats = t ? m_.b.heats_bed : m_.a.heats_bed;
      if (w_.flag & kS) {
        if (!heats) return skip(code('T', t, " has no heated bed")), true;
        bed_[t] = to_u32(w_.s);
        emit(actions::bed_temperature(tool(t), static_cast<std::uint16_t>(bed_[t])));
      } else if (w_.m == 140) {
        return skip("M140 without S (temperature)"), true;
      }
      if (w_.m == 140) return true;
      // gpx's precedence: T1 waits whenever B heats the bed; T0 only when a target is set.
      if (t ? m_.b.heats_bed : (m_.a.heats_bed && bed_[t] > 0))
        emit(actions::wait_for_platform(tool(t), 100, timeout));
      else if (!(w_.flag & kS))
        skip("no bed temperature to wait for");
      return true;
    }
    default: {  // M6, M116
      if (w_.m == 6 && target_tool_ != tool_) tool_change();
      if (m_.a.heats_bed && bed_[0] > 0)
        emit(actions::wait_for_platform(0, 100, timeout));
      else if (m_.b.heats_bed && bed_[1] > 0)
        emit(actions::wait_for_platform(1, 100, timeout));
      if (w_.m == 116 && !(w_.flag & kT)) {
        if (nozzle_[1] > 0) emit(actions::wait_for_tool(1, 100, timeout));
        if (nozzle_[0] > 0) emit(actions::wait_for_tool(0, 100, timeout));
      } else if (nozzle_[target_tool_] > 0) {
        emit(actions::wait_for_tool(tool(target_tool_), 100, timeout));
      }
      return true;
    }
  }
}

// M2 M73 M136 M137: the build's start, progress and end. False after M2: gpx reads no further.
bool Translator::m_build() {
  switch (w_.m) {
    case 2:
      if (state_ != State::ended) {
        end_build();
        emit(actions::build_end());
      }
      return false;
    case 73: {
      if (!(w_.flag & kP)) return skip("M73 without P (percent)"), true;
      const unsigned pct = std::min(to_u32(w_.p), 100u);
      if (state_ == State::ready && pct < 100) {
        start_build(pct);
      } else if (state_ != State::ended) {
        if (pct == 100) {
          end_build();
          if (opt_.build_end) emit(actions::build_end());
        } else if (percent_ < pct) {
          percent_ = pct;
          emit(actions::build_percent(static_cast<std::uint8_t>(pct)));
        }
      }
      return true;
    }
    case 136:
      if (state_ == State::ready) start_build(0);
      return true;
    case 137:
      if (state_ != State::ended) {
        end_build();
        emit(actions::build_end());
      }
      return true;
  }
  return true;
}

// gpx.c display_message: the text in 20-character packets (80 at most from the screen's origin),
// the last one with the timeout, and for M71 the wait for the button.
void Translator::display_message() {
  const bool wait = w_.m == 71;
  if (!wait && !(w_.flag & word::COMMENT))
    return skip(opt_.source.empty() ? "M70: its message is in a comment, which needs the file's text"
                                    : "M70 without a message (a comment)");
  std::string_view text = (w_.flag & word::COMMENT) ? std::string_view(w_.comment) : "Press M to continue";
  text = text.substr(0, text.find('\0'));
  const unsigned v = std::min((w_.flag & kY) ? to_u32(w_.y) : 0u, 3u);
  const unsigned h = std::min((w_.flag & kX) ? to_u32(w_.x) : 0u, 19u);
  const auto timeout = static_cast<std::uint8_t>((w_.flag & kP) ? static_cast<unsigned>(to_i32(w_.p)) : 0u);
  const std::size_t row = h ? 20 - h : 20;
  std::uint8_t options = 0;
  std::size_t length = text.size();
  if (v || h) {
    length = std::min(length, row);
    options |= 0x01;
  } else {
    length = std::min<std::size_t>(length, 80);
  }
  for (std::size_t sent = 0; sent < length;) {
    std::uint8_t seconds = 0;
    if (sent + row >= length) {
      seconds = timeout;
      options |= wait ? 0x06 : 0x02;
    }
    if (sent > 0) options |= 0x01;
    const std::size_t n = std::min(length - sent, row);
    emit(actions::display_message(options, static_cast<std::uint8_t>(h), static_cast<std::uint8_t>(v),
                                  seconds, text.substr(sent, n)));
    sent += n;
  }
}

bool Translator::m_code() {
  const int m = w_.m;
  if (is_query(m)) return skip("a host query, not an action (gpx writes it into the file anyway)"), true;
  const auto all_motors = static_cast<std::uint8_t>(m_.extruder_count == 1 ? (kXYZ | kA) : kAxes);
  const auto on = [&](bool dflt) { return (w_.flag & kS) ? to_u32(w_.s) != 0 : dflt; };
  const auto tool = static_cast<std::uint8_t>(target_tool_);
  switch (m) {
    case 0:
    case 22:
    case 26:
    case 30:
    case 31:
    case 110:
    case 111:
    case 112:
    case 400:
      return true;
    case 2:
    case 73:
    case 136:
    case 137:
      return m_build();
    case 6:
    case 104:
    case 109:
    case 116:
    case 133:
    case 134:
    case 140:
    case 190:
      return m_temperature();
    case 17:
    case 18:
      emit(actions::enable_axes(static_cast<std::uint8_t>((w_.flag & kAxes) ? (w_.flag & kAxes) : all_motors),
                                m == 17));
      return true;
    case 70:
    case 71:
      return display_message(), true;
    case 72:
      if (!(w_.flag & kP)) return skip("M72 without P (song)"), true;
      emit(actions::song(static_cast<std::uint8_t>(std::min(to_u32(w_.p), 2u))));
      return true;
    case 82:
      extruder_relative_ = false;
      return true;
    case 83:
      extruder_relative_ = true;
      return true;
    case 84:
      emit(actions::enable_axes(all_motors, false));
      return true;
    case 101:
    case 102:
    case 103:
      emit(actions::enable_axes(target_tool_ == 0 ? kA : kB, m != 103));
      return true;
    case 106:  // gpx's default RepRap flavour: M106/M107 drive the blower (extra output), like M126/M127
    case 126:
      emit(actions::tool_action(tool, 13, std::string(1, on(true) ? 1 : 0)));
      return true;
    case 107:
      emit(actions::tool_action(tool, 13, std::string(1, on(false) ? 1 : 0)));
      return true;
    case 127:
      emit(actions::tool_action(tool, 13, std::string(1, 0)));
      return true;
    case 108:
      if (w_.flag & kR) return skip("M108 R (simulated extruder RPM) is not translated"), true;
      if ((w_.flag & kT) && target_tool_ != tool_) tool_change();
      return true;
    case 131:
    case 132:
      if (!(w_.flag & kAxes)) return skip(code('M', m, " without axes (X Y Z A B)")), true;
      if (m == 131) return emit(actions::store_home(static_cast<std::uint8_t>(w_.flag & kAxes))), true;
      emit(actions::recall_home(static_cast<std::uint8_t>(w_.flag & kAxes)));
      set_unknown(w_.flag);
      // gpx: the extruders recall 0, so E moves stay relative to a known A/B.
      if (w_.flag & kA) known_ |= kA;
      if (w_.flag & kB) known_ |= kB;
      return true;
    case 135:
      if (target_tool_ != tool_) tool_change();
      return true;
    case 220:
      if ((w_.flag & kS) && w_.s > 0) speed_factor_ = to_u32(w_.s);
      return true;
    case 221:
      if ((w_.flag & kS) && w_.s > 0) extrusion_factor_[(w_.flag & kT) ? target_tool_ : tool_] = to_u32(w_.s);
      return true;
    case 300:
      emit(actions::beep(static_cast<std::uint16_t>((w_.flag & kS) ? to_u32(w_.s) & 0xFFFF : 300),
                         static_cast<std::uint16_t>((w_.flag & kP) ? to_u32(w_.p) & 0xFFFF : 1000)));
      return true;
    case 320:
    case 321:
      emit(actions::acceleration(m == 320));
      return true;
    default:
      return skip(code('M', m, " is not translated to s3g")), true;
  }
}

}  // namespace

Translation translate_gcode(const Program& gcode, const Machine& machine, const TranslateOptions& options) {
  Translation out;
  out.program.commands = gcode.size();
  Translator t(machine, options, out);
  for (std::size_t i = 0; i < gcode.size(); ++i) {
    if (t.command(gcode[i], i)) continue;
    if (i + 1 < gcode.size())  // M2: gpx reads no further
      out.skipped.push_back({gcode[i + 1].line, gcode[i + 1].text,
                             "after M2 (program end): it and the " + std::to_string(gcode.size() - i - 2) +
                                 " commands after it are not translated"});
    break;
  }
  t.finish();  // an empty file too gets 150 100 % and 154, as gpx writes them (source 0)
  return out;
}

std::string build_name_for(const std::string& output_path) {
  const std::size_t slash = output_path.rfind('/');
  std::string name = slash == std::string::npos ? output_path : output_path.substr(slash + 1);
  if (const std::size_t dot = name.rfind('.'); dot != std::string::npos) name.resize(dot);
  return name;
}

}  // namespace salient::protocol::s3g
