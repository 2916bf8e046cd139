// The s3g protocol's numbers (MakerBot's s3gProtocol.md, as Sailfish implements them): host
// queries (< 128, answered at once), queued actions (≥ 128, run in order from the command ring),
// the tool sub-commands, and the reply codes with what a host must do on each.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace salient::protocol::s3g {

// Host queries: answered at once, never queued.
enum class Query : std::uint8_t {
  version = 0,
  init = 1,
  buffer_space = 2,
  clear_buffer = 3,
  abort = 7,
  pause = 8,  // a toggle: confirm with build_stats
  tool_query = 10,
  is_finished = 11,
  reset = 17,
  position = 21,
  extended_stop = 22,
  board_status = 23,
  build_stats = 24,
  advanced_version = 27,
};

// Queued actions: acked when they fit in the ring, run in order, never validated by the board.
enum class Action : std::uint8_t {
  home_min = 131,
  home_max = 132,
  delay = 133,
  change_tool = 134,
  wait_for_tool = 135,
  tool_action = 136,
  enable_axes = 137,
  queue_point_ext = 139,
  set_position = 140,
  wait_for_platform = 141,
  queue_point_new = 142,
  store_home = 143,
  recall_home = 144,
  set_pot = 145,
  set_led = 146,
  set_beep = 147,
  wait_for_button = 148,
  display_message = 149,
  build_percent = 150,
  queue_song = 151,
  factory_reset = 152,
  build_start = 153,
  build_end = 154,
  queue_point = 155,  // x3g's: absolute steps, DDA rate, relative mask, distance, feed
  acceleration = 156,
  stream_version = 157,
  pause_at_z = 158,
};

// Tool sub-commands (query 10 and action 136).
enum class ToolCommand : std::uint8_t {
  get_temperature = 2,
  set_temperature = 3,
  fan = 12,
  extra_output = 13,
  is_ready = 22,
  platform_temperature = 30,
  set_platform_temperature = 31,
  target_temperature = 32,
  platform_target = 33,
  platform_ready = 35,
  status = 36,
};

// The first byte of every reply.
enum class Reply : std::uint8_t {
  generic_error = 0x80,  // noise, or a stray byte outside a packet: resend
  ok = 0x81,
  buffer_full = 0x82,  // not queued: wait for room, resend
  crc_mismatch = 0x83,
  packet_too_big = 0x84,
  unsupported = 0x85,  // unknown query
  downstream_timeout = 0x87,
  tool_lock_timeout = 0x88,
  cancelled = 0x89,  // cancelled on the printer (LCD, heater fault): this packet was not run
  building_from_sd = 0x8A,
  heater_shutdown = 0x8B,  // every later packet too
  packet_timeout = 0x8C,   // the packet was not complete 200 ms after its first byte
};

// What a host does on a reply (Sailfish's Host.cc, MakerBot's s3g driver).
enum class ReplyAction {
  accept,       // ok: the packet was taken
  resend,       // noise, CRC, timeout, tool lock: send the same packet again (bounded)
  wait_resend,  // buffer full: poll free space until it fits, resend (no bound)
  stop,         // cancelled, building from SD, heater shutdown: the print ends with its reason
  fatal,        // too big, unsupported, downstream timeout: a host bug or a broken board
};

ReplyAction action_of(std::uint8_t code);
// "buffer full", "heater shutdown", … ; "reply 0x91" for a code the protocol does not define.
std::string_view reply_name(std::uint8_t code);
bool is_reply_code(std::uint8_t code);

}  // namespace salient::protocol::s3g
