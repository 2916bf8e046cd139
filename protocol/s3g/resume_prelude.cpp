#include "protocol/s3g/resume_prelude.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/s3g_codes.hpp"

namespace salient::protocol::s3g {
namespace {

std::string action(Action a) {
  return std::string(1, static_cast<char>(a));
}

std::string tool_action(std::uint8_t tool, ToolCommand c, std::int16_t value) {
  std::string p = action(Action::tool_action);
  put_u8(p, tool), put_u8(p, static_cast<std::uint8_t>(c)), put_u8(p, 2), put_i16(p, value);
  return p;
}

std::string wait_for(Action a, std::uint8_t tool, std::uint16_t timeout_s) {
  std::string p = action(a);
  put_u8(p, tool), put_u16(p, 100), put_u16(p, timeout_s);
  return p;
}

// Queue point (155): `relative` bits make those axes deltas (A and B always: no extrusion).
std::string queue_point(const std::int32_t xyz[3], std::uint8_t relative, double steps, double seconds,
                        double distance_mm) {
  std::string p = action(Action::queue_point);
  for (int i = 0; i < 3; ++i) put_i32(p, xyz[i]);
  put_i32(p, 0), put_i32(p, 0);
  put_u32(p, static_cast<std::uint32_t>(std::max(1.0, steps / std::max(seconds, 1e-3))));
  put_u8(p, static_cast<std::uint8_t>(relative | 0x18));
  put_f32(p, static_cast<float>(distance_mm));
  put_u16(p, static_cast<std::uint16_t>(std::min(65535.0, distance_mm / std::max(seconds, 1e-3) * 64)));
  return p;
}

}  // namespace

std::vector<std::string> resume_prelude(const X3gProgram& program, std::size_t resume_from,
                                        const ResumeMotion& m) {
  if (resume_from == 0) return {};
  const std::size_t end = std::min(program.first_action_of(resume_from), program.actions.size());
  std::optional<std::int16_t> hotend[2], bed;
  std::optional<bool> fan;
  std::array<std::int32_t, 3> pos{};
  bool have_pos = false;
  std::vector<std::string> homing;
  bool moved = false;
  for (std::size_t i = 0; i < end; ++i) {
    const std::string& a = program.actions[i];
    const auto id = static_cast<std::uint8_t>(a[0]);
    std::size_t at = 1;
    try {
      if (id == static_cast<std::uint8_t>(Action::tool_action) && a.size() >= 5) {
        const std::uint8_t tool = static_cast<std::uint8_t>(a[1]) & 1;
        const auto c = static_cast<ToolCommand>(a[2]);
        at = 4;
        if (c == ToolCommand::set_temperature) hotend[tool] = get_i16(a, at);
        if (c == ToolCommand::set_platform_temperature) bed = get_i16(a, at);
        if (c == ToolCommand::fan) fan = get_u8(a, at) != 0;
      } else if (id == 155 || id == 142 || id == 139 || id == 140) {
        std::array<std::int32_t, 3> p{};
        for (auto& v : p) v = get_i32(a, at);
        std::uint8_t relative = 0;
        if (id == 155 && a.size() >= 26) relative = static_cast<std::uint8_t>(a[25]);
        if (id == 142 && a.size() >= 26) relative = static_cast<std::uint8_t>(a[25]);
        if (have_pos)
          for (int k = 0; k < 3; ++k)
            if (relative & (1 << k)) p[k] += pos[k];
        if (!have_pos && (relative & 0x07)) continue;  // a delta from an unknown place
        pos = p, have_pos = true;
        if (id != 140) moved = true;
        if (id == 140 && !moved) homing.push_back(a);
      } else if ((id == 131 || id == 132 || id == 144) && !moved) {
        homing.push_back(a);
        if (id != 144) have_pos = false;  // homed: where it is now comes from the file's next 140/144 or move
      }
    } catch (const std::out_of_range&) {
      continue;  // a truncated action (cannot come from split_x3g): nothing to learn from it
    }
  }
  std::vector<std::string> out;
  if (bed && *bed > 0) out.push_back(tool_action(0, ToolCommand::set_platform_temperature, *bed));
  for (std::uint8_t t = 0; t < 2; ++t)
    if (hotend[t] && *hotend[t] > 0) out.push_back(tool_action(t, ToolCommand::set_temperature, *hotend[t]));
  // Off the part first (a delta: the head may be anywhere), then home as the file did.
  const auto lift = static_cast<std::int32_t>(std::lround(m.lift_mm * m.z_steps_per_mm));
  const std::int32_t up[3] = {0, 0, lift};
  const double lift_s = m.lift_mm / m.z_feed_mm_s;
  out.push_back(queue_point(up, 0x07, lift, lift_s, m.lift_mm));
  if (m.rehome) out.insert(out.end(), homing.begin(), homing.end());
  if (bed && *bed > 0) out.push_back(wait_for(Action::wait_for_platform, 0, m.heat_timeout_s));
  for (std::uint8_t t = 0; t < 2; ++t)
    if (hotend[t] && *hotend[t] > 0) out.push_back(wait_for(Action::wait_for_tool, t, m.heat_timeout_s));
  if (fan)
    out.push_back(std::string{static_cast<char>(Action::tool_action), 0, 12, 1, static_cast<char>(*fan)});
  if (have_pos) {
    // Up to above the last layer where homing left the head (outside the part), over the last
    // X Y (its distance from home is not known: a fixed, slow duration), then down onto the part.
    const std::int32_t z_over = pos[2] + lift;
    const double z_mm = std::abs(z_over) / m.z_steps_per_mm;
    const std::int32_t rise[3] = {0, 0, z_over};
    out.push_back(queue_point(rise, 0x03, std::abs(z_over), z_mm / m.z_feed_mm_s, z_mm));
    const std::int32_t over[3] = {pos[0], pos[1], z_over};
    const double steps = std::max(std::abs(double(pos[0])), std::abs(double(pos[1])));
    out.push_back(queue_point(over, 0, steps, m.xy_travel_s, steps / m.xy_steps_per_mm));
    const std::int32_t down[3] = {pos[0], pos[1], pos[2]};
    out.push_back(queue_point(down, 0, lift, lift_s, m.lift_mm));
  }
  return out;
}

}  // namespace salient::protocol::s3g
