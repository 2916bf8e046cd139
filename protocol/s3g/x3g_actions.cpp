#include "protocol/s3g/x3g_actions.hpp"

#include <algorithm>
#include <initializer_list>

#include "protocol/s3g/packet.hpp"

namespace salient::protocol::s3g::actions {
namespace {

std::string id(std::uint8_t code) {
  return std::string(1, static_cast<char>(code));
}

std::string bytes(std::initializer_list<std::uint8_t> b) {
  return std::string(b.begin(), b.end());
}

void put_steps(std::string& out, const std::array<std::int32_t, 5>& steps) {
  for (std::int32_t s : steps) put_i32(out, s);
}

}  // namespace

std::string home(bool to_max, std::uint8_t axes, std::uint32_t us_per_step, std::uint16_t timeout_s) {
  std::string p = id(to_max ? 132 : 131);
  put_u8(p, axes);
  put_u32(p, us_per_step);
  put_u16(p, timeout_s);
  return p;
}

std::string delay(std::uint32_t ms) {
  std::string p = id(133);
  put_u32(p, ms);
  return p;
}

std::string change_tool(std::uint8_t tool) {
  std::string p = id(134);
  put_u8(p, tool);
  return p;
}

std::string wait_for_tool(std::uint8_t tool, std::uint16_t poll_ms, std::uint16_t timeout_s) {
  std::string p = id(135);
  put_u8(p, tool);
  put_u16(p, poll_ms);
  put_u16(p, timeout_s);
  return p;
}

std::string tool_action(std::uint8_t tool, std::uint8_t command, std::string_view data) {
  std::string p = id(136);
  put_u8(p, tool);
  put_u8(p, command);
  put_u8(p, static_cast<std::uint8_t>(data.size()));
  p += data;
  return p;
}

std::string nozzle_temperature(std::uint8_t tool, std::uint16_t celsius) {
  std::string t;
  put_u16(t, celsius);
  return tool_action(tool, 3, t);
}

std::string bed_temperature(std::uint8_t tool, std::uint16_t celsius) {
  std::string t;
  put_u16(t, celsius);
  return tool_action(tool, 31, t);
}

std::string enable_axes(std::uint8_t axes, bool enable) {
  std::string p = id(137);
  put_u8(p, static_cast<std::uint8_t>((axes & 0x1F) | (enable ? 0x80 : 0)));
  return p;
}

std::string queue_point_absolute(const std::array<std::int32_t, 5>& steps, std::uint32_t dda) {
  std::string p = id(139);
  put_steps(p, steps);
  put_u32(p, dda);
  return p;
}

std::string set_position(const std::array<std::int32_t, 5>& steps) {
  std::string p = id(140);
  put_steps(p, steps);
  return p;
}

std::string wait_for_platform(std::uint8_t tool, std::uint16_t poll_ms, std::uint16_t timeout_s) {
  std::string p = id(141);
  put_u8(p, tool);
  put_u16(p, poll_ms);
  put_u16(p, timeout_s);
  return p;
}

std::string store_home(std::uint8_t axes) {
  return bytes({143, axes});
}
std::string recall_home(std::uint8_t axes) {
  return bytes({144, axes});
}
std::string set_pot(std::uint8_t axis, std::uint8_t value) {
  return bytes({145, axis, value});
}

std::string beep(std::uint16_t hz, std::uint16_t ms) {
  std::string p = id(147);
  put_u16(p, hz);
  put_u16(p, ms);
  put_u8(p, 0);
  return p;
}

std::string display_message(std::uint8_t options, std::uint8_t h, std::uint8_t v, std::uint8_t timeout_s,
                            std::string_view text) {
  std::string p = bytes({149, options, h, v, timeout_s});
  p += text;
  p.push_back('\0');
  return p;
}

std::string build_percent(std::uint8_t percent) {
  return bytes({150, percent, 0});
}
std::string song(std::uint8_t song_id) {
  return bytes({151, song_id});
}

std::string build_start(std::string_view name) {
  std::string p = id(153);
  put_u32(p, 0);
  p += name.substr(0, std::min<std::size_t>(name.find('\0'), 24));
  p.push_back('\0');
  return p;
}

std::string build_end() {
  return bytes({154, 0});
}

std::string queue_point(const std::array<std::int32_t, 5>& steps, std::uint32_t dda_rate,
                        std::uint8_t relative, float distance_mm, std::uint16_t feed_x64) {
  std::string p = id(155);
  put_steps(p, steps);
  put_u32(p, dda_rate);
  put_u8(p, relative);
  put_f32(p, distance_mm);
  put_u16(p, feed_x64);
  return p;
}

std::string acceleration(bool on) {
  return bytes({156, static_cast<std::uint8_t>(on ? 1 : 0)});
}

}  // namespace salient::protocol::s3g::actions
