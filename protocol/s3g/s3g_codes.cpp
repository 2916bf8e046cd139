#include "protocol/s3g/s3g_codes.hpp"

namespace salient::protocol::s3g {

ReplyAction action_of(std::uint8_t code) {
  switch (static_cast<Reply>(code)) {
    case Reply::ok:
      return ReplyAction::accept;
    case Reply::generic_error:
    case Reply::crc_mismatch:
    case Reply::tool_lock_timeout:
    case Reply::packet_timeout:
      return ReplyAction::resend;
    case Reply::buffer_full:
      return ReplyAction::wait_resend;
    case Reply::cancelled:
    case Reply::building_from_sd:
    case Reply::heater_shutdown:
      return ReplyAction::stop;
    case Reply::packet_too_big:
    case Reply::unsupported:
    case Reply::downstream_timeout:
      return ReplyAction::fatal;
  }
  return ReplyAction::fatal;
}

bool is_reply_code(std::uint8_t code) {
  return code >= 0x80 && code <= 0x8C && code != 0x86;
}

std::string_view reply_name(std::uint8_t code) {
  switch (static_cast<Reply>(code)) {
    case Reply::generic_error:
      return "generic error";
    case Reply::ok:
      return "ok";
    case Reply::buffer_full:
      return "buffer full";
    case Reply::crc_mismatch:
      return "CRC mismatch";
    case Reply::packet_too_big:
      return "packet too big";
    case Reply::unsupported:
      return "command not supported";
    case Reply::downstream_timeout:
      return "downstream timeout";
    case Reply::tool_lock_timeout:
      return "tool lock timeout";
    case Reply::cancelled:
      return "build cancelled on the printer";
    case Reply::building_from_sd:
      return "the printer is building from its SD card";
    case Reply::heater_shutdown:
      return "heater shutdown (a heater fault)";
    case Reply::packet_timeout:
      return "packet timeout (incomplete packet)";
  }
  return "unknown reply code";
}

}  // namespace salient::protocol::s3g
