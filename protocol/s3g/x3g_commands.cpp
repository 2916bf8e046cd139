#include "protocol/s3g/x3g_commands.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/s3g_codes.hpp"

namespace salient::protocol::s3g {

namespace {

// Fixed part of each action after its id (s3gProtocol.md; GPX's s3g.c agrees). -1: not an action.
// 136 adds its length byte's count; 149 and 153 end at a NUL.
struct ActionInfo {
  int fixed = -1;
  const char* name = nullptr;
};

constexpr std::array<ActionInfo, 256> make_table() {
  std::array<ActionInfo, 256> t{};
  t[131] = {7, "home to minimum"};
  t[132] = {7, "home to maximum"};
  t[133] = {4, "delay"};
  t[134] = {1, "change tool"};
  t[135] = {5, "wait for tool"};
  t[136] = {3, "tool action"};
  t[137] = {1, "enable/disable axes"};
  t[139] = {24, "queue point extended"};
  t[140] = {20, "set position"};
  t[141] = {5, "wait for platform"};
  t[142] = {25, "queue point new"};
  t[143] = {1, "store home positions"};
  t[144] = {1, "recall home positions"};
  t[145] = {2, "set digital potentiometer"};
  t[146] = {5, "set RGB LED"};
  t[147] = {5, "set beep"};
  t[148] = {4, "wait for button"};
  t[149] = {4, "display message"};
  t[150] = {2, "build percentage"};
  t[151] = {1, "queue song"};
  t[152] = {1, "reset to factory"};
  t[153] = {4, "build start"};
  t[154] = {1, "build end"};
  t[155] = {31, "queue point"};
  t[156] = {1, "acceleration toggle"};
  t[157] = {20, "stream version"};
  t[158] = {4, "pause at Z"};
  return t;
}
constexpr auto kActions = make_table();

std::string hex(std::uint8_t b) {
  const char* digits = "0123456789ABCDEF";
  return std::string("0x") + digits[b >> 4] + digits[b & 15];
}

}  // namespace

X3gError::X3gError(std::size_t at, const std::string& what)
    : std::runtime_error("x3g byte " + std::to_string(at) + ": " + what), offset(at) {}

const char* action_name(std::uint8_t id) {
  return kActions[id].name;
}

std::optional<std::size_t> action_length(std::string_view bytes) {
  if (bytes.empty()) return std::nullopt;
  const auto id = static_cast<std::uint8_t>(bytes[0]);
  const ActionInfo& info = kActions[id];
  if (info.fixed < 0)
    throw X3gError(0, "id " + std::to_string(id) + " (" + hex(id) + ") is not an s3g action");
  std::size_t length = 1 + static_cast<std::size_t>(info.fixed);
  if (id == static_cast<std::uint8_t>(Action::tool_action)) {
    if (bytes.size() < 4) return std::nullopt;
    length += static_cast<unsigned char>(bytes[3]);
  } else if (id == static_cast<std::uint8_t>(Action::display_message) ||
             id == static_cast<std::uint8_t>(Action::build_start)) {
    // The text runs to its NUL, within a packet.
    const std::size_t limit = std::min(bytes.size(), kMaxPayload);
    std::size_t end = length;
    while (end < limit && bytes[end] != '\0') ++end;
    if (end >= limit) {
      if (bytes.size() < kMaxPayload) return std::nullopt;
      throw X3gError(0, std::string(info.name) + ": text without its NUL within 32 bytes");
    }
    length = end + 1;
  }
  if (length > kMaxPayload)
    throw X3gError(0,
                   std::string(info.name) + " of " + std::to_string(length) + " bytes (a packet holds 32)");
  if (bytes.size() < length) return std::nullopt;
  return length;
}

std::vector<std::string> split_x3g(std::string_view file) {
  std::vector<std::string> out;
  std::size_t at = 0;
  while (at < file.size()) {
    std::optional<std::size_t> n;
    try {
      n = action_length(file.substr(at));
    } catch (const X3gError& e) {
      throw X3gError(at, std::string(e.what()).substr(std::string(e.what()).find(": ") + 2));
    }
    if (!n) {
      const auto id = static_cast<std::uint8_t>(file[at]);
      throw X3gError(at, std::string(action_name(id)) + " cut short by the end of the file");
    }
    out.emplace_back(file.substr(at, *n));
    at += *n;
  }
  return out;
}

}  // namespace salient::protocol::s3g
