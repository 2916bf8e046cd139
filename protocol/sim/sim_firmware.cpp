// SimFirmware. Times: the driver's clock in microseconds. Motion and heating happen in printer
// seconds, turned into wall time by time_scale / heat_time_scale (0: instant).
#include "protocol/sim/sim_firmware.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol::sim {
namespace {

constexpr double kKeepaliveSeconds = 2;  // Marlin's DEFAULT_KEEPALIVE_INTERVAL
constexpr double kHomingSeconds = 4;
constexpr Micros kBusyEvery{2000000};  // busy-for's keepalive: the same 2 s, in wall time

Micros wall(double seconds) {
  return Micros(static_cast<long long>(std::llround(seconds * 1e6)));
}

std::string_view first_word(std::string_view c) {
  return c.substr(0, c.find(' '));
}

// The commands that make Marlin wait, and so send busy keepalives.
bool waits(std::string_view code) {
  return code == "G4" || code == "G28" || code == "M400" || code == "M109" || code == "M190";
}

std::optional<double> param(std::string_view c, char letter) {
  for (std::size_t at = c.find(' '); at != std::string_view::npos; at = c.find(' ', at + 1)) {
    if (at + 1 >= c.size() || c[at + 1] != letter) continue;
    double v = 0;
    const char* begin = c.data() + at + 2;
    const auto [ptr, ec] = std::from_chars(begin, c.data() + c.size(), v);
    if (ec == std::errc() && ptr != begin) return v;
    return 0.0;  // a bare letter ("G28 X")
  }
  return std::nullopt;
}

// Seconds for a move of `d` mm at `v` mm/s with acceleration `a`, from and to rest.
double trapezoid_seconds(double d, double v, double a) {
  if (d <= 0) return 0;
  if (v <= 0) v = 1;
  if (a <= 0) return d / v;
  if (d < v * v / a) return 2 * std::sqrt(d / a);  // a triangle: never reaches v
  return d / v + v / a;
}

}  // namespace

SimFirmware::SimFirmware(SimConfig config)
    : config_(config), in_(config.baud / 10), out_(config.baud / 10), rng_(config.faults.seed) {
  hotend_.rate = config_.hotend_rate;
  bed_.rate = config_.bed_rate;
}

double SimFirmware::heat_scale() const {
  return config_.heat_time_scale < 0 ? config_.time_scale : config_.heat_time_scale;
}

Micros SimFirmware::scaled(double printer_seconds, double scale) const {
  return Micros(static_cast<long long>(std::llround(printer_seconds * scale * 1e6)));
}

void SimFirmware::say(std::string_view line, Micros now) {
  std::string l(line);
  l += '\n';
  out_.push(l, now);
}

void SimFirmware::boot(Micros now) {
  say("start", now);
  say("echo:Marlin 2.1.2 (salient-sim)", now);
  say("echo: Last Updated: 2026-11-22 | Author: (salient-sim)", now);
}

void SimFirmware::ok(const Command& c, Micros now) {
  std::string l = "ok";
  if (config_.advanced_ok) {
    if (c.number) l += " N" + std::to_string(*c.number);
    l += " P" + std::to_string(config_.planner_blocks - planner_.size());
    l += " B" + std::to_string(config_.bufsize - queue_.size());  // the current command still holds its slot
  }
  send_ok(std::move(l), stats_.executed, now);
}

// Every ok goes out here, so that the faults on oks apply to all alike. `command`: the one it
// answers; 0 for the ok after a Resend, which answers none.
void SimFirmware::send_ok(std::string line, long long command, Micros now) {
  std::bernoulli_distribution drop(config_.faults.drop_ok);
  if (config_.faults.drop_ok > 0 && drop(rng_)) {
    ++stats_.oks_dropped;
    return;
  }
  if (command != 0 && command == config_.faults.malformed_ok) {
    line[1] = '\0';  // a framing error reads as a zero byte on most UARTs
    ++stats_.oks_malformed;
  }
  say(line, now);
}

void SimFirmware::receive(std::string_view bytes, Micros now) {
  if (state_ == State::disconnected) return;
  in_.push(bytes, now);
}

void SimFirmware::scan_emergency(std::string_view line, Micros now) {
  // The emergency parser sees bytes as they arrive, before the receive buffer and the queue.
  std::string_view c = line;
  while (!c.empty() && (c.front() == ' ')) c.remove_prefix(1);
  if (!c.empty() && c.front() == 'N') {
    const std::size_t sp = c.find(' ');
    c = sp == std::string_view::npos ? std::string_view{} : c.substr(sp + 1);
  }
  c = c.substr(0, c.find('*'));
  while (!c.empty() && (c.back() == ' ' || c.back() == '\r')) c.remove_suffix(1);
  if (c == "M112")
    kill("Printer halted. kill() called!", now);
  else if (c == "M108")
    abort_wait_ = true;
  else if (c == "M410")
    planner_.clear();
}

void SimFirmware::line_error(std::string_view what, Micros now) {
  ++stats_.lines_rejected;
  say("Error:" + std::string(what) + ", Last Line: " + std::to_string(last_n_), now);
  request_resend(now);
}

// Marlin's flush_and_request_resend: the receive buffer is emptied, and so is the rest of a
// line that was half in it (modelled: Marlin would take that tail for a command of its own).
void SimFirmware::request_resend(Micros now) {
  const std::size_t nl = rx_.find_last_of('\n');
  flushing_ = nl == std::string::npos ? !rx_.empty() : nl + 1 < rx_.size();
  rx_.clear();
  say("Resend: " + std::to_string(last_n_ + 1), now);
  if (!config_.faults.resend_without_ok) send_ok("ok", 0, now);
}

// rerequest: a line that passed every check is refused all the same, once. Only a numbered line
// can be asked for again, so it is the first from command N on (N counts what is queued too).
bool SimFirmware::rerequested(Micros now) {
  const long long at = config_.faults.rerequest;
  const long long command = stats_.executed + static_cast<long long>(queue_.size()) + 1;
  if (!at || rerequest_done_ || command < at) return false;
  rerequest_done_ = true;
  ++stats_.lines_rerequested;
  request_resend(now);
  return true;
}

void SimFirmware::read_commands(Micros now) {
  while (queue_.size() < config_.bufsize && state_ == State::running) {
    const std::size_t nl = rx_.find_first_of("\n\r");
    if (nl == std::string::npos) return;
    std::string line = rx_.substr(0, nl);
    rx_.erase(0, nl + 1);
    if (flushing_) {
      flushing_ = false;
      continue;
    }
    ++stats_.lines_received;
    if (config_.faults.noise > 0 && line.size() > 1 &&
        std::bernoulli_distribution(config_.faults.noise)(rng_)) {
      // One byte changes, never the leading N: an unnumbered line is accepted unchecked, so no
      // host could notice that, and never into a line end or a comment.
      static constexpr std::string_view alphabet = "0123456789GMXYZEF ";
      const std::size_t at = std::uniform_int_distribution<std::size_t>(1, line.size() - 1)(rng_);
      char c = line[at];
      while (c == line[at])
        c = alphabet[std::uniform_int_distribution<std::size_t>(0, alphabet.size() - 1)(rng_)];
      line[at] = c;
      ++stats_.lines_corrupted;
    }
    std::string_view s = line;
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    if (s.empty()) continue;
    Command cmd;
    if (s.front() == 'N') {
      // Marlin's order: line number, then a checksum exists, then it matches.
      const bool m110 = s.find("M110") != std::string_view::npos;
      long long n = 0;
      std::from_chars(s.data() + 1, s.data() + s.size(), n);
      if (m110) {  // "N5 M110 N0": the counter comes from M110's own N
        const std::size_t m = s.find("M110"), star = s.find('*');
        if (auto n2 = param(s.substr(m, star == std::string_view::npos ? star : star - m), 'N'))
          n = static_cast<long long>(*n2);
      }
      if (n != last_n_ + 1 && !m110) return line_error("Line Number is not Last Line Number+1", now);
      const std::size_t star = s.rfind('*');
      if (star == std::string_view::npos) return line_error("No Checksum with line number", now);
      int sum = -1;
      std::from_chars(s.data() + star + 1, s.data() + s.size(), sum);
      if (sum != marlin::checksum(s.substr(0, star))) return line_error("checksum mismatch", now);
      if (!m110 && rerequested(now)) return;  // M110 sets the counter: there is no line to ask for
      last_n_ = n;
      cmd.number = n;
      const std::size_t sp = s.find(' ');
      s = sp == std::string_view::npos || sp > star ? std::string_view{} : s.substr(sp + 1, star - sp - 1);
    }
    cmd.text = marlin::strip_comment(s);
    if (cmd.text.empty()) continue;
    queue_.push_back(std::move(cmd));
  }
}

void SimFirmware::update_heaters(Micros now) {
  const double dt = static_cast<double>((now - heaters_at_).count()) / 1e6;
  heaters_at_ = now;
  const double scale = heat_scale();
  for (Heater* h : {&hotend_, &bed_}) {
    const double goal = h->target > 0 ? h->target : 21;
    if (scale <= 0) {
      h->temperature = goal;
      continue;
    }
    const double step = h->rate * dt / scale;
    h->temperature = h->temperature < goal ? std::min(goal, h->temperature + step)
                                           : std::max(goal, h->temperature - step / 2);
  }
}

std::string SimFirmware::temperature_report() const {
  char buf[128];
  std::snprintf(buf, sizeof buf, "T:%.2f /%.2f B:%.2f /%.2f @:%d B@:%d", hotend_.temperature, hotend_.target,
                bed_.temperature, bed_.target, hotend_.temperature < hotend_.target ? 127 : 0,
                bed_.temperature < bed_.target ? 127 : 0);
  return buf;
}

bool SimFirmware::move(const Command& c, Micros now) {
  if (planner_.size() >= config_.planner_blocks) return false;  // wait for a free block
  static constexpr char axes[4] = {'X', 'Y', 'Z', 'E'};
  double delta[4] = {0, 0, 0, 0};
  const double from_x = pos_[0], from_y = pos_[1];
  for (int i = 0; i < 4; ++i) {
    const auto v = param(c.text, axes[i]);
    if (!v) continue;
    const bool rel = i == 3 ? relative_e_ || relative_ : relative_;
    const double target = rel ? pos_[i] + *v : *v;
    delta[i] = target - pos_[i];
    pos_[i] = target;
  }
  if (auto f = param(c.text, 'F'); f && *f > 0) feed_mm_s_ = *f / 60;
  double d = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  const std::string_view code = first_word(c.text);
  const auto i_word = param(c.text, 'I'), j_word = param(c.text, 'J');
  if ((code == "G2" || code == "G3") && (i_word || j_word)) {
    // ARC_SUPPORT: about (x + I, y + J), counter-clockwise for G3; a full turn when it ends where
    // it starts. It takes the time of its length along the arc.
    const double cx = from_x + i_word.value_or(0), cy = from_y + j_word.value_or(0);
    const double r = std::hypot(from_x - cx, from_y - cy);
    const double a0 = std::atan2(from_y - cy, from_x - cx), a1 = std::atan2(pos_[1] - cy, pos_[0] - cx);
    double sweep = code == "G3" ? a1 - a0 : a0 - a1;
    while (sweep <= 1e-12) sweep += 2 * M_PI;
    d = std::hypot(r * sweep, delta[2]);
  }
  if (d == 0) d = std::abs(delta[3]);
  if (config_.time_scale <= 0 || d == 0) return true;
  const Micros start = std::max(now, planner_free_at_);
  planner_free_at_ =
      start + scaled(trapezoid_seconds(d, feed_mm_s_, config_.acceleration), config_.time_scale);
  planner_.push_back(planner_free_at_);
  return true;
}

SimFirmware::Outcome SimFirmware::execute(const Command& c, Micros now) {
  using O = Outcome;
  const std::string_view code = first_word(c.text);
  const bool first = !head_started_;
  head_started_ = true;
  if (code == "G0" || code == "G1" || code == "G2" || code == "G3")
    return move(c, now) ? O::done : O::blocked;
  if (code == "G28" || code == "G4" || code == "M400") {
    if (!planner_.empty()) return O::blocked;  // these wait for every move to finish
    if (first || head_until_ == Micros{0}) {
      double seconds = 0;
      if (code == "G28") seconds = kHomingSeconds;
      if (code == "G4") seconds = param(c.text, 'S').value_or(param(c.text, 'P').value_or(0) / 1000);
      head_until_ = now + scaled(seconds, config_.time_scale);
      if (code == "G28") pos_[0] = pos_[1] = pos_[2] = 0;
    }
    return now >= head_until_ ? O::done : O::blocked;
  }
  if (code == "M104" || code == "M140" || code == "M109" || code == "M190") {
    Heater& h = code == "M104" || code == "M109" ? hotend_ : bed_;
    if (first) {
      h.target = param(c.text, 'S').value_or(param(c.text, 'R').value_or(0));
      if (code == "M104" || code == "M140") return O::done;
      heating_wait_ = true;
      abort_wait_ = false;
      next_heat_report_ = now + scaled(1, heat_scale());
      update_heaters(now);
      const double gap = std::max(0.0, std::abs(h.target - h.temperature) - 0.5);
      head_until_ = now + scaled(gap / h.rate, heat_scale()) + Micros(1);  // when to look again
    }
    const bool reached = std::abs(h.temperature - (h.target > 0 ? h.target : 21)) < 1 || h.target <= 0;
    if (reached || abort_wait_) {
      heating_wait_ = false;
      next_heat_report_ = Micros::max();
      return O::done;
    }
    return O::blocked;
  }
  if (code == "M105") {
    // Its reply is the ok ("ok T:…"), without ADVANCED_OK's fields; dropped like any ok.
    send_ok("ok " + temperature_report(), stats_.executed + 1, now);
    return O::replied;
  }
  if (code == "M155") {
    const double s = param(c.text, 'S').value_or(0);
    if (config_.autoreport) {
      autoreport_every_ = Micros(static_cast<long long>(s * 1e6));
      next_autoreport_ = s > 0 ? now + autoreport_every_ : Micros::max();
    } else {
      say("echo:Unknown command: \"" + c.text + "\"", now);
    }
    return O::done;
  }
  if (code == "M115") {
    say("FIRMWARE_NAME:Marlin 2.1.2 (salient-sim) SOURCE_CODE_URL:github.com/MarlinFirmware/Marlin "
        "PROTOCOL_VERSION:1.0 MACHINE_TYPE:salient-sim EXTRUDER_COUNT:1 "
        "UUID:00000000-0000-0000-0000-000000000000",
        now);
    say(std::string("Cap:AUTOREPORT_TEMP:") + (config_.autoreport ? "1" : "0"), now);
    say(std::string("Cap:EMERGENCY_PARSER:") + (config_.emergency_parser ? "1" : "0"), now);
    say("Cap:EEPROM:0", now);
    return O::done;
  }
  if (code == "M112") return O::halt;
  if (code == "M204") {
    if (auto a = param(c.text, 'P').value_or(param(c.text, 'S').value_or(0)); a > 0) config_.acceleration = a;
    return O::done;
  }
  if (code == "G90")
    relative_ = false;
  else if (code == "G91")
    relative_ = true;
  else if (code == "M82")
    relative_e_ = false;
  else if (code == "M83")
    relative_e_ = true;
  else if (code == "G92") {
    static constexpr char axes[4] = {'X', 'Y', 'Z', 'E'};
    for (int i = 0; i < 4; ++i)
      if (auto v = param(c.text, axes[i])) pos_[i] = *v;
  } else if (code.empty() || (code[0] != 'G' && code[0] != 'M' && code[0] != 'T')) {
    say("echo:Unknown command: \"" + c.text + "\"", now);
  }
  return O::done;
}

void SimFirmware::kill(std::string_view why, Micros now) {
  say("Error:" + std::string(why), now);
  state_ = State::halted;
  queue_.clear();
  planner_.clear();
  rx_.clear();
  hotend_.target = bed_.target = 0;
}

// A reboot: what the board held is gone, and so are its timers. Our counters and log stay.
void SimFirmware::clear(Micros now) {
  state_ = State::running;
  rx_.clear();
  incoming_.clear();
  flushing_ = false;
  queue_.clear();
  planner_.clear();
  planner_free_at_ = now;
  last_n_ = 0;
  hotend_.target = bed_.target = 0;
  head_started_ = heating_wait_ = abort_wait_ = false;
  head_until_ = hold_until_ = Micros{0};
  next_busy_ = next_heat_report_ = Micros::max();
  autoreport_every_ = Micros{0};
  next_autoreport_ = Micros::max();
}

void SimFirmware::reset(Micros now) {
  clear(now);
  boot(now);
}

void SimFirmware::port_opened(Micros now) {
  if (!config_.faults.reset_on_open || state_ == State::disconnected) return;
  // What was on its way either side dies with the board (the bootloader, then the sketch).
  in_.clear();
  out_.clear();
  clear(now);
  state_ = State::booting;
  deaf_until_ = now + wall(config_.faults.boot_for);
  wake(now);  // boot-for=0: at once
}

// silent-for or boot-for is up: what reached the board until then was lost.
void SimFirmware::wake(Micros now) {
  if (!deaf() || now < deaf_until_) return;
  stats_.bytes_ignored += static_cast<long long>(in_.pop(deaf_until_).size());
  const bool booted = state_ == State::booting;
  state_ = State::running;
  if (booted) boot(now);
}

// busy-for: the command is held before it runs, as a long one would be, with keepalives: a host
// must tell a printer that is busy from one that went silent.
bool SimFirmware::held(Micros now) {
  const SimFaults& f = config_.faults;
  if (hold_until_ == Micros{0}) {
    if (f.busy_for <= 0 || busy_done_) return false;
    const long long command = stats_.executed + 1;
    if (f.busy_at ? command != f.busy_at : !waits(first_word(queue_.front().text))) return false;
    busy_done_ = true;
    hold_until_ = now + wall(f.busy_for);
    next_busy_ = now + kBusyEvery;
  }
  if (now < hold_until_) return true;
  hold_until_ = Micros{0};
  next_busy_ = Micros::max();  // the command's own wait, if any, keeps its own time
  return false;
}

void SimFirmware::after_executed(Outcome outcome, Micros now) {
  executed_.push_back(queue_.front().text);
  ++stats_.executed;
  const SimFaults& f = config_.faults;
  if (outcome == Outcome::halt) return kill("Printer halted. kill() called!", now);
  if (f.thermal_runaway_at && stats_.executed == f.thermal_runaway_at) {
    say("Error:Thermal Runaway, system stopped! Heater_ID: 0", now);
    return kill("Printer halted. kill() called!", now);
  }
  if (f.reset_after && stats_.executed == f.reset_after) return reset(now);
  if (outcome == Outcome::done) ok(queue_.front(), now);
  queue_.pop_front();
  head_started_ = false;
  head_until_ = Micros{0};
  next_busy_ = Micros::max();
  if (f.silent_after && stats_.executed == f.silent_after) {
    state_ = State::silent;  // after its ok: the host has every command it ran confirmed
    deaf_until_ = f.silent_for > 0 ? now + wall(f.silent_for) : Micros::max();
  }
  if (f.disconnect_after && stats_.executed == f.disconnect_after) state_ = State::disconnected;
}

void SimFirmware::keepalive(Micros now) {
  if (heating_wait_ && now >= next_heat_report_) {
    say(temperature_report() + " W:?", now);
    next_heat_report_ = now + std::max(Micros(1000), scaled(1, heat_scale()));
  }
  if (next_busy_ != Micros::max() && now >= next_busy_) {
    say("echo:busy: processing", now);
    next_busy_ = now + busy_every();
  }
  if (now >= next_autoreport_) {
    say(temperature_report(), now);
    next_autoreport_ = now + autoreport_every_;
  }
}

Micros SimFirmware::busy_every() const {
  if (hold_until_ != Micros{0}) return kBusyEvery;
  return std::max(Micros(1000), scaled(kKeepaliveSeconds, heating_wait_ ? heat_scale() : config_.time_scale));
}

void SimFirmware::advance(Micros now) {
  if (state_ == State::disconnected) return;
  wake(now);
  if (deaf()) {
    stats_.bytes_ignored += static_cast<long long>(in_.pop(now).size());
    return;
  }
  const std::string arrived = in_.pop(now);
  for (char ch : arrived) {
    if (ch == '\n' || ch == '\r') {
      if (state_ == State::halted && !incoming_.empty()) ++stats_.lines_after_halt;
      if (config_.emergency_parser && state_ == State::running) scan_emergency(incoming_, now);
      incoming_.clear();
    } else if (incoming_.size() < 256) {
      incoming_ += ch;
    }
    if (state_ != State::running) continue;
    if (rx_.size() < config_.rx_buffer_bytes)
      rx_ += ch;
    else
      ++stats_.rx_overflow_bytes;
  }
  if (state_ != State::running) return;
  while (!planner_.empty() && planner_.front() <= now) planner_.pop_front();
  update_heaters(now);
  while (state_ == State::running) {
    read_commands(now);
    if (queue_.empty()) break;
    const Outcome outcome = held(now) ? Outcome::blocked : execute(queue_.front(), now);
    if (outcome == Outcome::blocked) {
      if (next_busy_ == Micros::max())
        next_busy_ = now + scaled(kKeepaliveSeconds, heating_wait_ ? heat_scale() : config_.time_scale);
      break;
    }
    after_executed(outcome, now);
  }
  if (state_ == State::running) keepalive(now);
}

std::string SimFirmware::take_output(Micros now) {
  return out_.pop(now);
}

Micros SimFirmware::next_wakeup() const {
  Micros t = std::min(in_.next_arrival(), out_.next_arrival());
  if (deaf()) return std::min(t, deaf_until_);
  if (state_ != State::running) return t;
  if (!queue_.empty()) {
    if (!planner_.empty()) t = std::min(t, planner_.front());
    if (head_until_ != Micros{0}) t = std::min(t, head_until_);
    if (hold_until_ != Micros{0}) t = std::min(t, hold_until_);
    if (heating_wait_) t = std::min(t, next_heat_report_);
    t = std::min(t, next_busy_);
  }
  t = std::min(t, next_autoreport_);
  return t;
}

}  // namespace salient::protocol::sim
