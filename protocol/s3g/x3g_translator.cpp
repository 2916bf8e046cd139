#include "protocol/s3g/x3g_translator.hpp"

#include <algorithm>
#include <array>
#include <string_view>

#include "protocol/s3g/x3g_translator_state.hpp"

namespace salient::protocol::s3g {
namespace detail {
namespace {

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

}  // namespace

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

}  // namespace detail

Translation translate_gcode(const Program& gcode, const Machine& machine, const TranslateOptions& options) {
  Translation out;
  out.program.commands = gcode.size();
  detail::Translator t(machine, options, out);
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
