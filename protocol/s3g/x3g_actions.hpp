// Encoders for the s3g actions the translator writes: each returns one payload (id first, fields
// little-endian, as s3gProtocol.md lays them out), ready to frame or to append to an .x3g file.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace salient::protocol::s3g::actions {

// 131/132: home `axes` (bit 0 X … bit 4 B) to their minimum or maximum.
std::string home(bool to_max, std::uint8_t axes, std::uint32_t us_per_step, std::uint16_t timeout_s);
std::string delay(std::uint32_t ms);                                                           // 133
std::string change_tool(std::uint8_t tool);                                                    // 134
std::string wait_for_tool(std::uint8_t tool, std::uint16_t poll_ms, std::uint16_t timeout_s);  // 135
std::string tool_action(std::uint8_t tool, std::uint8_t command, std::string_view data);       // 136
std::string nozzle_temperature(std::uint8_t tool, std::uint16_t celsius);                      // 136/3
std::string bed_temperature(std::uint8_t tool, std::uint16_t celsius);                         // 136/31
std::string enable_axes(std::uint8_t axes, bool enable);                                       // 137
// 139: absolute steps, unaccelerated, at `dda` µs per step.
std::string queue_point_absolute(const std::array<std::int32_t, 5>& steps, std::uint32_t dda);
std::string set_position(const std::array<std::int32_t, 5>& steps);                                // 140
std::string wait_for_platform(std::uint8_t tool, std::uint16_t poll_ms, std::uint16_t timeout_s);  // 141
std::string store_home(std::uint8_t axes);                                                         // 143
std::string recall_home(std::uint8_t axes);                                                        // 144
std::string set_pot(std::uint8_t axis, std::uint8_t value);                                        // 145
std::string beep(std::uint16_t hz, std::uint16_t ms);                                              // 147
// 149: up to 20 characters of a message at column `h`, row `v` (`options` bit 0 keeps the screen,
// bit 1 ends a message group, bit 2 waits for the button).
std::string display_message(std::uint8_t options, std::uint8_t h, std::uint8_t v, std::uint8_t timeout_s,
                            std::string_view text);
std::string build_percent(std::uint8_t percent);  // 150
std::string song(std::uint8_t id);                // 151
std::string build_start(std::string_view name);   // 153 (name cut at 24)
std::string build_end();                          // 154
// 155: XYZ absolute (unless `relative` says so) and AB steps, steps/s on the longest axis, the
// move's length in mm, and its feed in mm/s × 64.
std::string queue_point(const std::array<std::int32_t, 5>& steps, std::uint32_t dda_rate,
                        std::uint8_t relative, float distance_mm, std::uint16_t feed_x64);
std::string acceleration(bool on);  // 156

}  // namespace salient::protocol::s3g::actions
