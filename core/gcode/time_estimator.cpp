// estimate_gcode. Each move becomes a block (length, unit direction over X Y Z E, nominal speed,
// acceleration). The speed at a junction follows Marlin's classic jerk (Planner::add); a backward pass
// caps entries by what deceleration allows, a forward pass caps exits by what acceleration
// allows; each block then runs a trapezoid (or a triangle). Dwells and heating waits are stops.
#include "core/gcode/time_estimator.hpp"

#include <algorithm>
#include <cmath>

#include "core/common/input_error.hpp"
#include "core/gcode/gcode_line.hpp"
#include "core/mesh/text_cursor.hpp"

namespace salient::core {
namespace {

struct Block {
  double length;
  double u[4];    // unit direction over X Y Z E at the start…
  double out[4];  // …and at the end (they differ on an arc)
  double speed, accel;
  double entry = 0, exit = 0;  // planned speeds
  double safe = 0;             // speed it may start at from rest
  std::size_t layer;
  std::size_t command;  // index into the command timings, when kept
};

double trapezoid_time(const Block& b) {
  const double a = b.accel, v0 = b.entry, v1 = b.exit, vc = std::max(b.speed, std::max(v0, v1));
  const double da = (vc * vc - v0 * v0) / (2 * a), dd = (vc * vc - v1 * v1) / (2 * a);
  if (da + dd <= b.length) return (vc - v0) / a + (vc - v1) / a + (b.length - da - dd) / vc;
  const double peak = std::sqrt(std::max(0.0, (2 * a * b.length + v0 * v0 + v1 * v1) / 2));
  return std::max(0.0, (peak - v0) / a) + std::max(0.0, (peak - v1) / a);
}

class Planner {
 public:
  Planner(MachineLimits& limits, GcodeEstimate& out, std::vector<CommandTiming>* commands)
      : limits_(limits), out_(out), commands_(commands) {}

  // Junction speed as Marlin's classic jerk computes it: both blocks scaled to the smaller
  // nominal speed; per axis the "jerk" is the change of velocity when the axis keeps its
  // direction, but only the larger magnitude when it reverses; over the limit the junction
  // speed is scaled down. If both blocks could start from rest at more than that, their safe
  // speed is used instead.
  void add(Block b) {
    b.safe = safe_speed(b);
    if (!blocks_.empty()) {
      const Block& p = blocks_.back();
      const bool prev_larger = p.speed > b.speed;
      const double factor = prev_larger ? b.speed / p.speed : p.speed / b.speed;
      double v = prev_larger ? b.speed : p.speed;
      double scale = 1;
      for (int k = 0; k < 4; ++k) {
        const double v_exit = p.out[k] * p.speed * factor * scale, v_entry = b.u[k] * b.speed * scale;
        const double jerk =
            v_exit > v_entry ? ((v_entry > 0 || v_exit < 0) ? v_exit - v_entry : std::max(v_exit, -v_entry))
                             : ((v_entry < 0 || v_exit > 0) ? v_entry - v_exit : std::max(-v_exit, v_entry));
        if (jerk > limits_.jerk[k]) scale *= limits_.jerk[k] / jerk;
      }
      v *= scale;
      if (p.safe > 0.99 * v && b.safe > 0.99 * v) v = b.safe;
      junction_.push_back(v);
    }
    blocks_.push_back(b);
  }

  // The speed a block may start at from rest (or end at into rest).
  double safe_speed(const Block& b) const {
    double v = b.speed;
    bool limited = false;
    for (int k = 0; k < 4; ++k) {
      const double axis_speed = std::fabs(b.u[k]) * b.speed;
      if (axis_speed <= limits_.jerk[k]) continue;
      if (!limited) {
        v = limits_.jerk[k];
        limited = true;
      } else if (axis_speed * v > limits_.jerk[k] * b.speed) {
        v = limits_.jerk[k] * b.speed / axis_speed;
      }
    }
    return v;
  }

  // Plans and times everything queued; the machine comes to rest after the last block.
  void flush() {
    const std::size_t n = blocks_.size();
    if (n == 0) return;
    blocks_[0].entry = blocks_[0].safe;
    for (std::size_t i = 1; i < n; ++i) blocks_[i].entry = junction_[i - 1];
    blocks_[n - 1].exit = blocks_[n - 1].safe;
    for (std::size_t i = n; i-- > 0;) {  // backward: decelerate in time for what follows
      Block& b = blocks_[i];
      if (i + 1 < n) b.exit = blocks_[i + 1].entry;
      b.entry = std::min(b.entry, std::sqrt(b.exit * b.exit + 2 * b.accel * b.length));
    }
    for (std::size_t i = 0; i < n; ++i) {  // forward: accelerate no faster than possible
      Block& b = blocks_[i];
      if (i > 0) b.entry = std::min(b.entry, blocks_[i - 1].exit);
      b.exit = std::min(b.exit, std::sqrt(b.entry * b.entry + 2 * b.accel * b.length));
      if (i + 1 < n) blocks_[i + 1].entry = std::min(blocks_[i + 1].entry, b.exit);
    }
    for (const Block& b : blocks_) {
      const double t = trapezoid_time(b);
      add_time(b.layer, t);
      if (commands_) (*commands_)[b.command].seconds += t;
    }
    blocks_.clear();
    junction_.clear();
  }

  void add_time(std::size_t layer, double seconds) {
    out_.seconds += seconds;
    if (out_.layer_seconds.size() <= layer) out_.layer_seconds.resize(layer + 1, 0);
    out_.layer_seconds[layer] += seconds;
  }

 private:
  MachineLimits& limits_;
  GcodeEstimate& out_;
  std::vector<CommandTiming>* commands_;
  std::vector<Block> blocks_;
  std::vector<double> junction_;
};

// The command's text as a host sends it: no comment, no surrounding blanks.
CommandTiming command_text(std::string_view line) {
  line = line.substr(0, line.find(';'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\t' || line.back() == '\r'))
    line.remove_suffix(1);
  while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
  CommandTiming c;
  c.bytes = static_cast<std::uint32_t>(line.size());
  for (char ch : line) c.xor_sum ^= static_cast<std::uint8_t>(ch);
  return c;
}

void extend_printing_area(GcodeEstimate& out, const double* from, const double* to) {
  for (int k = 0; k < 3; ++k) {
    const double lo = std::min(from[k], to[k]), hi = std::max(from[k], to[k]);
    out.printing_min[k] = out.printed ? std::min(out.printing_min[k], lo) : lo;
    out.printing_max[k] = out.printed ? std::max(out.printing_max[k], hi) : hi;
  }
  out.printed = true;
}

}  // namespace

GcodeEstimate estimate_gcode(std::string_view text, const std::string& source, MachineLimits limits,
                             std::vector<CommandTiming>* commands, const CancelToken* cancel) {
  GcodeEstimate out;
  Planner planner(limits, out, commands);
  TextCursor cur(text, source);
  double pos[4] = {0, 0, 0, 0};
  double feed = 1500.0 / 60;  // mm/s
  bool absolute = true, absolute_e = true, inches = false;
  std::size_t layer = 0;
  bool saw_layer_mark = false;
  std::size_t moves_at_mark = 0;  // PrusaSlicer's and Cura's marks for the same layer count once
  std::string_view line;
  while (cur.next_line(line)) {
    ++out.lines;
    if (cancel && out.lines % 4096 == 0 && cancel->cancelled()) throw Cancelled();
    GcodeError error;
    const GcodeLine g = parse_gcode_line(line, error);
    if (error != GcodeError::none)
      cur.fail(error == GcodeError::bad_number
                   ? "malformed number in '" + std::string(line.substr(0, 60)) + "'"
                   : "not a G-code word in '" + std::string(line.substr(0, 60)) + "'");
    if (!g.letter) {
      if (g.comment.starts_with("LAYER_CHANGE") || g.comment.starts_with("LAYER:")) {
        // The first mark opens the first layer: moves before it (the start code's homing and prime
        // line) count with it rather than as a layer of their own.
        if (saw_layer_mark && out.moves > moves_at_mark) ++layer;
        saw_layer_mark = true;
        moves_at_mark = out.moves;
      }
      continue;
    }
    if (commands) commands->push_back(command_text(line));
    const double unit = inches ? 25.4 : 1.0;
    if (g.letter == 'G' && (g.number == 0 || g.number == 1 || g.number == 2 || g.number == 3)) {
      if (g.has('F')) feed = g.get('F') * unit / 60;
      double target[4];
      const char axes[4] = {'X', 'Y', 'Z', 'E'};
      for (int k = 0; k < 4; ++k) {
        const bool abs_axis = k == 3 ? absolute_e : absolute;
        target[k] = g.has(axes[k]) ? (abs_axis ? 0 : pos[k]) + g.get(axes[k]) * unit : pos[k];
      }
      double d[4];
      for (int k = 0; k < 4; ++k) d[k] = target[k] - pos[k];
      double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      double start_tangent[2] = {0, 0}, end_tangent[2] = {0, 0}, arc_xy = 0;
      const bool arc = (g.number == 2 || g.number == 3) && (g.has('I') || g.has('J'));
      if (arc) {
        // Arc in XY about (x + I, y + J): its length, not its chord; a full turn when it ends
        // where it starts (as Marlin reads it).
        const double cx = pos[0] + g.get('I') * unit, cy = pos[1] + g.get('J') * unit;
        const double r = std::hypot(pos[0] - cx, pos[1] - cy);
        double a0 = std::atan2(pos[1] - cy, pos[0] - cx), a1 = std::atan2(target[1] - cy, target[0] - cx);
        double sweep = g.number == 3 ? a1 - a0 : a0 - a1;
        while (sweep <= 1e-12) sweep += 2 * M_PI;
        arc_xy = r * sweep;
        length = std::hypot(arc_xy, d[2]);
        const double turn = g.number == 3 ? 1 : -1;  // tangent: the radius turned a quarter that way
        if (r > 0) {
          start_tangent[0] = -turn * (pos[1] - cy) / r, start_tangent[1] = turn * (pos[0] - cx) / r;
          end_tangent[0] = -turn * (target[1] - cy) / r, end_tangent[1] = turn * (target[0] - cx) / r;
        }
      }
      out.filament_mm += d[3];  // a retraction subtracts what its unretraction adds back
      if (d[3] > 0 && length > 0) extend_printing_area(out, pos, target);
      const double span = length > 0 ? length : std::fabs(d[3]);
      std::copy(target, target + 4, pos);
      if (!(span > 1e-9)) continue;
      Block b{};
      b.length = span;
      for (int k = 0; k < 4; ++k) b.u[k] = b.out[k] = d[k] / span;
      if (arc)
        for (int k = 0; k < 2; ++k)
          b.u[k] = start_tangent[k] * arc_xy / span, b.out[k] = end_tangent[k] * arc_xy / span;
      b.command = commands ? commands->size() - 1 : 0;
      b.speed = feed;
      const bool extruding = d[3] > 0 && length > 0;
      b.accel = length == 0 ? limits.retract_acceleration
                : extruding ? limits.acceleration
                            : limits.travel_acceleration;
      for (int k = 0; k < 4; ++k) {
        if (std::fabs(b.u[k]) < 1e-12) continue;
        b.speed = std::min(b.speed, limits.max_feedrate[k] / std::fabs(b.u[k]));
        b.accel = std::min(b.accel, limits.max_axis_acceleration[k] / std::fabs(b.u[k]));
      }
      b.layer = layer;
      planner.add(b);
      ++out.moves;
    } else if (g.letter == 'G' && g.number == 4) {
      planner.flush();
      const double dwell = g.has('S') ? g.get('S') : g.get('P') / 1000;
      planner.add_time(layer, dwell);
      if (commands) commands->back().seconds += dwell;
    } else if (g.letter == 'G' && g.number == 20) {
      inches = true;
    } else if (g.letter == 'G' && g.number == 21) {
      inches = false;
    } else if (g.letter == 'G' && g.number == 90) {
      absolute = absolute_e = true;
    } else if (g.letter == 'G' && g.number == 91) {
      absolute = absolute_e = false;
    } else if (g.letter == 'M' && g.number == 82) {
      absolute_e = true;
    } else if (g.letter == 'M' && g.number == 83) {
      absolute_e = false;
    } else if (g.letter == 'G' && g.number == 92) {
      const char axes[4] = {'X', 'Y', 'Z', 'E'};
      const bool any = g.has('X') || g.has('Y') || g.has('Z') || g.has('E');
      for (int k = 0; k < 4; ++k)
        if (g.has(axes[k]) || !any) pos[k] = g.get(axes[k]) * unit;
    } else if (g.letter == 'G' && g.number == 28) {
      planner.flush();
      pos[0] = pos[1] = pos[2] = 0;
    } else if (g.letter == 'M' &&
               (g.number == 109 || g.number == 190 || g.number == 116 || g.number == 400)) {
      planner.flush();
      if (g.number != 400) ++out.heating_waits;
    } else if (g.letter == 'M' && g.number == 204) {
      if (g.has('S')) limits.acceleration = limits.travel_acceleration = g.get('S');
      if (g.has('P')) limits.acceleration = g.get('P');
      if (g.has('T')) limits.travel_acceleration = g.get('T');
      if (g.has('R')) limits.retract_acceleration = g.get('R');
    } else if (g.letter == 'M' && (g.number == 201 || g.number == 203 || g.number == 205)) {
      const char axes[4] = {'X', 'Y', 'Z', 'E'};
      for (int k = 0; k < 4; ++k) {
        if (!g.has(axes[k]) || !(g.get(axes[k]) > 0)) continue;
        if (g.number == 201) limits.max_axis_acceleration[k] = g.get(axes[k]);
        if (g.number == 203) limits.max_feedrate[k] = g.get(axes[k]);
        if (g.number == 205) limits.jerk[k] = g.get(axes[k]);
      }
    }
  }
  planner.flush();
  if (out.layer_seconds.empty()) out.layer_seconds.push_back(0);
  return out;
}

}  // namespace salient::core
