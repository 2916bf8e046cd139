#include "protocol/serial/s3g_link.hpp"

#include <algorithm>
#include <stdexcept>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/resume_prelude.hpp"
#include "protocol/serial/link_events.hpp"

namespace salient::protocol::serial {
namespace {

using Clock = std::chrono::steady_clock;
using s3g::Millis;

std::chrono::microseconds micros(Clock::duration d) {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::max(d, Clock::duration::zero()));
}

}  // namespace

S3gLink::S3gLink(std::unique_ptr<Transport> transport, S3gLinkConfig config)
    : transport_(std::move(transport)), config_(std::move(config)), start_(Clock::now()) {}

Millis S3gLink::since_start() const {
  return std::chrono::duration_cast<Millis>(Clock::now() - start_);
}

FirmwareInfo S3gLink::handshake() {
  transport_->discard_input();
  for (int attempt = 0; attempt < config_.handshake_attempts; ++attempt) {
    s3g::S3gSession session(config_.session);  // a fresh one: nothing of a half answer
    session.handshake(since_start());
    std::string error;
    const auto until = Clock::now() + config_.handshake_timeout;
    while (Clock::now() < until && request_.load() != kInterrupt && !session.handshake_done()) {
      if (std::string out = session.take_output(); !out.empty()) transport_->write(out);
      for (const s3g::SessionEvent& e : session.take_events())
        if (e.kind == s3g::SessionEvent::Kind::error) error = e.text;
      if (!error.empty()) throw LinkError(transport_->describe() + ": " + error);
      const auto left = std::min<Clock::duration>(until - Clock::now(), std::chrono::milliseconds(50));
      const std::string bytes = transport_->read(micros(left));
      if (!bytes.empty()) session.on_receive(bytes, since_start());
      session.on_tick(since_start());
    }
    if (request_.load() == kInterrupt)
      throw LinkError(transport_->describe() + ": connecting was interrupted");
    if (!session.handshake_done()) continue;
    firmware_ = FirmwareInfo{};
    firmware_.name = session.firmware_name();
    firmware_.emergency_parser = true;  // queries (abort, extended stop) act at once, ring or not
    idle_ = std::make_unique<s3g::S3gSession>(config_.session);
    idle_->heard(since_start());
    return firmware_;
  }
  throw LinkError(transport_->describe() + ": no answer to the s3g version query after " +
                  std::to_string(config_.handshake_attempts) +
                  " tries: is it a MakerBot/Sailfish board, and is the baud rate right (115200)?");
}

void S3gLink::idle(std::chrono::milliseconds duration, const LinkEventFn& on_event) {
  if (!idle_) idle_ = std::make_unique<s3g::S3gSession>(config_.session);
  s3g::S3gSession& session = *idle_;
  const auto until = Clock::now() + duration;
  const auto pass = [&] {
    if (std::string out = session.take_output(); !out.empty()) transport_->write(out);
    for (const s3g::SessionEvent& e : session.take_events()) {
      if (e.kind == s3g::SessionEvent::Kind::timeout) throw LinkError(transport_->describe() + ": " + e.text);
      if (!on_event) continue;
      if (auto out = to_link_event(e, e.done)) on_event(*out);
    }
  };
  session.on_tick(since_start());
  pass();
  while (Clock::now() < until) {
    const auto left = std::min<Clock::duration>(until - Clock::now(), std::chrono::milliseconds(50));
    const std::string bytes = transport_->read(micros(left));
    if (!bytes.empty()) session.on_receive(bytes, since_start());
    session.on_tick(since_start());
    pass();
  }
}

void S3gLink::halt_now() {
  transport_->write(s3g::frame(std::string{22, 0x03}));
}

PrintResult S3gLink::print(std::shared_ptr<const Program> program, const LinkEventFn& on_event,
                           std::size_t resume_from) {
  if (!config_.translate) {
    PrintResult r;
    r.total = program ? program->size() : 0;
    r.confirmed = std::min(resume_from, r.total);
    r.reason = "G-code over s3g needs the translator (G-code → x3g); print an .x3g file instead";
    return r;
  }
  std::shared_ptr<const s3g::X3gProgram> x3g;
  try {
    x3g = std::make_shared<const s3g::X3gProgram>(config_.translate(program ? *program : Program{}));
  } catch (const std::exception& e) {
    PrintResult r;
    r.total = program ? program->size() : 0;
    r.reason = std::string("cannot translate the G-code to x3g: ") + e.what();
    return r;
  }
  return print_x3g(std::move(x3g), on_event, resume_from);
}

PrintResult S3gLink::print_x3g(std::shared_ptr<const s3g::X3gProgram> program, const LinkEventFn& on_event,
                               std::size_t resume_from) {
  std::vector<std::string> prelude;
  if (program && resume_from > 0)
    prelude = config_.resume_prelude ? config_.resume_prelude(*program, resume_from)
                                     : s3g::resume_prelude(*program, resume_from);
  return print_x3g(std::move(program), on_event, resume_from, std::move(prelude));
}

PrintResult S3gLink::print_x3g(std::shared_ptr<const s3g::X3gProgram> program, const LinkEventFn& on_event,
                               std::size_t resume_from, std::vector<std::string> prelude) {
  using s3g::SessionState;
  const auto t0 = Clock::now();
  auto now = [&] { return std::chrono::duration_cast<Millis>(Clock::now() - t0); };
  s3g::S3gSession session(config_.session);
  // A request made before the stream began (the printer says "printing" as soon as the print is
  // queued) is this print's: it is kept, and cleared when the print ends so none carries over.
  struct ClearRequest {
    std::atomic<int>& request;
    ~ClearRequest() { request = kNone; }
  } clear_request{request_};
  PrintResult result;
  try {
    session.begin(std::move(program), now(), resume_from, std::move(prelude));
  } catch (const std::invalid_argument& e) {
    result.reason = e.what();
    result.confirmed = resume_from;
    return result;
  }
  auto finish = [&] {
    result.end = end_of(session.state());
    result.confirmed = session.commands_done();
    result.total = session.commands_total();
    result.lines_resent = session.packets_resent();
    result.pokes = session.timeouts();
    result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    doubts_ = session.doubts_resolved();
    if (idle_) idle_->heard(since_start());
    return result;
  };
  Millis give_up = Millis::max();
  try {
    for (;;) {
      switch (request_.exchange(kNone)) {
        case kPause:
          session.pause();
          break;
        case kResume:
          session.resume(now());
          break;
        case kCancel:
          session.cancel(s3g::S3gSession::cancel_cleanup(), now());
          break;
        case kInterrupt:
          // The ring runs out (what was confirmed is done), then the heaters go off.
          session.cancel(s3g::S3gSession::heaters_off(), now(), false);
          give_up = now() + config_.interrupt_wait;
          break;
        case kEmergency:
          session.emergency_stop(s3g::S3gSession::heaters_off(), now());
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
      for (const s3g::SessionEvent& e : session.take_events()) {
        using K = s3g::SessionEvent::Kind;
        if ((e.kind == K::failed || (e.kind == K::cancelled && e.text != "cancelled")) &&
            result.reason.empty())
          result.reason = e.text;
        if (!on_event) continue;
        if (auto out = to_link_event(e, e.done)) on_event(*out);
      }
      const SessionState s = session.state();
      if (s == SessionState::finished || s == SessionState::failed ||
          (s == SessionState::cancelled && session.idle()))
        return finish();
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
