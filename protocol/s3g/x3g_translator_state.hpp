// The translator's state machine: gpx.c's parser state (positions, what is known, the carried
// extruder remainder, feed rate, tools, temperatures, the build) and its handlers, one Program
// command at a time. Internal to translate_gcode (x3g_translator.cpp: commands and the build;
// x3g_motion.cpp: moves, homing, tool changes).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "protocol/gcode/program.hpp"
#include "protocol/s3g/gcode_words.hpp"
#include "protocol/s3g/machine.hpp"
#include "protocol/s3g/x3g_actions.hpp"
#include "protocol/s3g/x3g_translator.hpp"

namespace salient::protocol::s3g::detail {

inline constexpr unsigned kX = word::X, kY = word::Y, kZ = word::Z, kA = word::A, kB = word::B,
                          kXYZ = word::XYZ, kAxes = word::AXES, kE = word::E, kF = word::F, kP = word::P,
                          kR = word::R, kS = word::S, kG = word::G, kM = word::M, kT = word::T;
inline constexpr unsigned kNozzleMax = 280;      // °C: gpx clamps M104/M109 here
inline constexpr unsigned kMaxTimeout = 0xFFFF;  // s: the waits' default timeout

// gpx's casts as gcc compiles them on x86-64: a double out of range becomes INT32_MIN for (int)
// and 0 for (unsigned) (cvttsd2si), instead of undefined behaviour.
inline std::int32_t to_i32(double v) {
  if (!(v >= -2147483648.0 && v < 2147483648.0)) return INT32_MIN;
  return static_cast<std::int32_t>(v);
}
inline std::uint32_t to_u32(double v) {
  if (!(v > -9.2233720368547758e18 && v < 9.2233720368547758e18)) return 0;
  return static_cast<std::uint32_t>(static_cast<std::int64_t>(v));
}
inline std::int64_t to_i64(double v) {
  if (!(v > -9.2233720368547758e18 && v < 9.2233720368547758e18)) return INT64_MIN;
  return static_cast<std::int64_t>(v);
}

// "M104 without S": built by appending (GCC 12 warns falsely on "M" + std::to_string(n)).
inline std::string code(char letter, long n, std::string_view rest) {
  std::string s(1, letter);
  s.append(std::to_string(n)).append(rest);
  return s;
}

struct Vec5 {
  double x = 0, y = 0, z = 0, a = 0, b = 0;
};

inline double magnitude(unsigned flag, const Vec5& v) {
  double acc = 0.0;
  if (flag & kX) acc = v.x * v.x;
  if (flag & kY) acc += v.y * v.y;
  if (flag & kZ) acc += v.z * v.z;
  if (flag & kA) acc += v.a * v.a;
  if (flag & kB) acc += v.b * v.b;
  return std::sqrt(acc);
}

inline double largest_axis(unsigned flag, const Vec5& v) {
  double r = 0.0;
  if (flag & kX) r = std::fabs(v.x);
  if (flag & kY) r = std::max(r, std::fabs(v.y));
  if (flag & kZ) r = std::max(r, std::fabs(v.z));
  if (flag & kA) r = std::max(r, std::fabs(v.a));
  if (flag & kB) r = std::max(r, std::fabs(v.b));
  return r;
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

}  // namespace salient::protocol::s3g::detail
