// What MarlinLink and S3gLink share in turning their session's vocabulary into the link's: the
// events a host needs, and how a print ended. Both sessions' events and states use the same names
// (acknowledged, temperatures, resend, error, reset; finished, cancelled), so one template serves.
// Internal to protocol/serial/*.cpp.
#pragma once

#include <cstddef>
#include <optional>

#include "protocol/link/printer_link.hpp"

namespace salient::protocol::serial {

// The session's events a host needs (the rest — firmware, capability, timeout, finished… — is the
// link's own business or in the PrintResult). `done`: the commands an acknowledgement confirms.
template <typename SessionEvent>
std::optional<LinkEvent> to_link_event(const SessionEvent& e, std::size_t done) {
  using K = typename SessionEvent::Kind;
  LinkEvent out;
  out.kind = LinkEvent::Kind::progress;
  switch (e.kind) {
    case K::acknowledged:
      out.done = done;
      return out;
    case K::temperatures:
      out.kind = LinkEvent::Kind::temperatures;
      out.hotend = e.temperatures.hotend, out.hotend_target = e.temperatures.hotend_target;
      out.bed = e.temperatures.bed, out.bed_target = e.temperatures.bed_target;
      return out;
    case K::resend:
      out.kind = LinkEvent::Kind::resend;
      return out;
    case K::error:
      out.kind = LinkEvent::Kind::error, out.text = e.text;
      return out;
    case K::reset:
      out.kind = LinkEvent::Kind::reset, out.text = e.text;
      return out;
    default:
      return std::nullopt;
  }
}

template <typename SessionState>
PrintEnd end_of(SessionState s) {
  if (s == SessionState::finished) return PrintEnd::finished;
  if (s == SessionState::cancelled) return PrintEnd::cancelled;
  return PrintEnd::failed;
}

}  // namespace salient::protocol::serial
