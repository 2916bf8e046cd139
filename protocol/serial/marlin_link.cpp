#include "protocol/serial/marlin_link.hpp"

#include <algorithm>
#include <utility>

#include "protocol/marlin/resume_prelude.hpp"
#include "protocol/serial/link_events.hpp"

namespace salient::protocol::serial {
namespace {

using Clock = std::chrono::steady_clock;
using marlin::Millis;

}  // namespace

MarlinLink::MarlinLink(std::unique_ptr<Transport> transport, LinkConfig config)
    : transport_(std::move(transport)), config_(std::move(config)), start_(Clock::now()) {}

marlin::Millis MarlinLink::since_start() const {
  return std::chrono::duration_cast<Millis>(Clock::now() - start_);
}

// Sends an unnumbered command to a listening session's printer and passes on what it answers
// until its ok; false on timeout, or as soon as an interrupt is asked for (the daemon stops
// while a silent board is being asked).
bool MarlinLink::exchange(marlin::MarlinSession& listener, const std::string& command,
                          std::vector<marlin::SessionEvent>& heard) {
  transport_->write(command + "\n");
  const std::size_t oks = listener.oks_heard();
  const auto until = Clock::now() + config_.handshake_timeout;
  while (Clock::now() < until && request_.load() != kInterrupt) {
    const auto left = std::min<Clock::duration>(until - Clock::now(), std::chrono::milliseconds(50));
    listener.on_receive(transport_->read(std::chrono::duration_cast<std::chrono::microseconds>(left)),
                        since_start());
    for (marlin::SessionEvent& e : listener.take_events()) heard.push_back(std::move(e));
    if (listener.oks_heard() > oks) return true;
  }
  return false;
}

FirmwareInfo MarlinLink::handshake() {
  using Kind = marlin::SessionEvent::Kind;
  transport_->discard_input();
  transport_->write("\n");  // ends whatever half line the firmware may hold
  for (int attempt = 0; attempt < config_.handshake_attempts; ++attempt) {
    marlin::MarlinSession listener(config_.session);  // a fresh one: nothing of a half answer
    std::vector<marlin::SessionEvent> heard;
    const bool answered = exchange(listener, "M115", heard);
    if (request_.load() == kInterrupt)
      throw LinkError(transport_->describe() + ": connecting was interrupted");
    if (!answered) continue;
    for (const marlin::SessionEvent& e : heard) {
      if (e.kind == Kind::firmware) firmware_.name = e.text;
      if (e.kind == Kind::capability && e.text == "EMERGENCY_PARSER") firmware_.emergency_parser = true;
      if (e.kind == Kind::capability && e.text == "AUTOREPORT_TEMP") firmware_.autoreport_temperature = true;
    }
    config_.session.emergency_parser = firmware_.emergency_parser;
    if (firmware_.autoreport_temperature && config_.autoreport_seconds > 0)
      exchange(listener, "M155 S" + std::to_string(config_.autoreport_seconds), heard);
    config_.session.autoreport_temperature = firmware_.autoreport_temperature;
    idle_ = std::make_unique<marlin::MarlinSession>(config_.session);
    idle_->heard(since_start());
    return firmware_;
  }
  throw LinkError(transport_->describe() + ": no answer to M115 after " +
                  std::to_string(config_.handshake_attempts) +
                  " tries: is it a Marlin printer, and is the baud rate right?");
}

void MarlinLink::idle(std::chrono::milliseconds duration, const LinkEventFn& on_event) {
  if (!idle_) idle_ = std::make_unique<marlin::MarlinSession>(config_.session);
  marlin::MarlinSession& session = *idle_;
  const auto until = Clock::now() + duration;
  // What the printer says is the session's to interpret; here only bytes and time move.
  const auto pass = [&] {
    if (std::string out = session.take_output(); !out.empty()) transport_->write(out);
    for (const marlin::SessionEvent& e : session.take_events()) {
      if (e.kind == marlin::SessionEvent::Kind::timeout)
        throw LinkError(transport_->describe() + ": " + e.text);
      if (!on_event) continue;
      if (auto out = to_link_event(e, static_cast<std::size_t>(e.line))) on_event(*out);
    }
  };
  session.on_tick(since_start());
  pass();
  while (Clock::now() < until) {
    const std::string bytes =
        transport_->read(std::chrono::duration_cast<std::chrono::microseconds>(until - Clock::now()));
    if (!bytes.empty()) session.on_receive(bytes, since_start());
    pass();
  }
  session.on_tick(since_start());
  pass();
}

bool MarlinLink::send(const std::vector<std::string>& lines) {
  std::lock_guard lock(send_mutex_);
  to_send_.insert(to_send_.end(), lines.begin(), lines.end());
  return true;
}

std::vector<std::string> MarlinLink::take_to_send() {
  std::lock_guard lock(send_mutex_);
  return std::exchange(to_send_, {});
}

PrintResult MarlinLink::print(std::shared_ptr<const Program> program, const LinkEventFn& on_event,
                              std::size_t resume_from) {
  using marlin::SessionState;
  const auto t0 = Clock::now();
  auto now = [&] { return std::chrono::duration_cast<Millis>(Clock::now() - t0); };
  marlin::MarlinSession session(config_.session);
  // A request made before the stream began (the printer says "printing" as soon as the print is
  // queued) is this print's: it is kept, and cleared when the print ends so none carries over.
  struct ClearRequest {
    std::atomic<int>& request;
    ~ClearRequest() { request = kNone; }
  } clear_request{request_};
  const std::vector<std::string> prelude =
      program && resume_from > 0 ? marlin::resume_prelude(*program, resume_from) : std::vector<std::string>{};
  session.begin(std::move(program), now(), resume_from, prelude);
  PrintResult result;
  auto finish = [&] {
    result.end = end_of(session.state());
    result.confirmed = session.commands_done();
    result.total = session.commands_total();
    result.lines_resent = session.lines_resent();
    result.pokes = session.pokes_sent();
    result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    result.halted = session.halted();
    result.unsent = take_to_send();
    if (idle_) idle_->heard(since_start());  // the print's own replies count for the time between prints
    return result;
  };
  // A daemon that stops gives the printer this long to take the heaters-off lines, then goes.
  Millis give_up = Millis::max();
  try {
    for (;;) {
      const int request = request_.exchange(kNone);
      // Console lines go before the request read with them: they were asked for before it (a line
      // sent, then a cancel, goes ahead of the cleanup). Once the print is ending they wait in
      // to_send_ and come back as unsent, for between prints.
      const bool console_goes =
          session.state() == SessionState::printing || session.state() == SessionState::paused;
      if (std::vector<std::string> lines = console_goes ? take_to_send() : std::vector<std::string>{};
          !lines.empty())
        session.send_now(lines, now());
      switch (request) {
        case kPause:
          session.pause();
          break;
        case kResume:
          session.resume(now());
          break;
        case kCancel:
          session.cancel(config_.cancel_gcode, now());
          break;
        case kInterrupt:
          session.cancel({"M104 S0", "M140 S0", "M107"}, now());
          give_up = now() + config_.interrupt_wait;
          break;
        case kEmergency:
          session.emergency_stop();
          break;
        default:
          break;
      }
      if (now() >= give_up) {
        if (std::string out = session.take_output(); !out.empty()) transport_->write(out);
        result.reason = "the printer did not confirm the heaters off within " +
                        std::to_string(config_.interrupt_wait.count()) + " ms";
        return finish();
      }
      if (std::string out = session.take_output(); !out.empty()) transport_->write(out);
      for (const marlin::SessionEvent& e : session.take_events()) {
        if (e.kind == marlin::SessionEvent::Kind::failed && result.reason.empty()) result.reason = e.text;
        if (!on_event) continue;
        if (auto out = to_link_event(e, static_cast<std::size_t>(e.line))) on_event(*out);
      }
      const SessionState s = session.state();
      if (s == SessionState::finished || s == SessionState::failed ||
          (s == SessionState::cancelled && session.idle()))
        return finish();
      // Wake for the session's next deadline, and at least every 50 ms for requests.
      const Millis left = std::clamp(session.deadline() - now(), Millis(0), Millis(50));
      const std::string bytes = transport_->read(std::chrono::duration_cast<std::chrono::microseconds>(left));
      if (!bytes.empty()) session.on_receive(bytes, now());
      session.on_tick(now());
    }
  } catch (const LinkError& e) {
    result.disconnected = true;
    result.reason = e.what();
    finish();
    result.end = PrintEnd::failed;
    return result;
  }
}

}  // namespace salient::protocol::serial
