// parse_reply. Fatal errors are those after which Marlin calls kill(): the firmware halts and
// must be reset (thermal runaway, MINTEMP/MAXTEMP, "Printer halted").
#include "protocol/marlin/marlin_reply.hpp"

#include <cctype>
#include <charconv>

namespace salient::protocol::marlin {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

bool starts_with(std::string_view s, std::string_view p) {
  return s.substr(0, p.size()) == p;
}

std::optional<double> number_after(std::string_view s, std::size_t at) {
  while (at < s.size() && s[at] == ' ') ++at;
  double v = 0;
  auto [ptr, ec] = std::from_chars(s.data() + at, s.data() + s.size(), v);
  if (ec != std::errc() || ptr == s.data() + at) return std::nullopt;
  return v;
}

std::optional<long long> integer_after(std::string_view s, std::size_t at) {
  while (at < s.size() && (s[at] == ' ' || s[at] == 'N' || s[at] == ':')) ++at;
  long long v = 0;
  auto [ptr, ec] = std::from_chars(s.data() + at, s.data() + s.size(), v);
  if (ec != std::errc() || ptr == s.data() + at) return std::nullopt;
  return v;
}

// "T:210.0 /210.0 B:60.1 /60.0 @:64 B@:0" (with or without the targets).
Temperatures parse_temperatures(std::string_view s) {
  Temperatures t;
  auto read = [&](std::string_view key, std::optional<double>& value, std::optional<double>& target) {
    for (std::size_t at = s.find(key); at != std::string_view::npos; at = s.find(key, at + 1)) {
      if (at > 0 && s[at - 1] != ' ') continue;  // "B@:" and "T0:" are other things
      value = number_after(s, at + key.size());
      const std::size_t slash = s.find('/', at + key.size());
      const std::size_t next = s.find(' ', at + key.size() + 1);
      if (slash != std::string_view::npos && (next == std::string_view::npos || slash <= next + 1))
        target = number_after(s, slash + 1);
      return;
    }
  };
  read("T:", t.hotend, t.hotend_target);
  read("B:", t.bed, t.bed_target);
  return t;
}

}  // namespace

MarlinReply parse_reply(std::string_view raw) {
  MarlinReply r;
  const std::string_view s = trim(raw);
  r.text = std::string(s);
  if (s == "ok" || starts_with(s, "ok ")) {
    r.kind = ReplyKind::ok;
    for (std::size_t at = 3; at < s.size(); ++at) {
      if (s[at - 1] != ' ') continue;
      if (s[at] == 'N') r.line = integer_after(s, at + 1);
      if (s[at] == 'P') r.planner_free = static_cast<int>(integer_after(s, at + 1).value_or(-1));
      if (s[at] == 'B' && at + 1 < s.size() && std::isdigit(static_cast<unsigned char>(s[at + 1])))
        r.buffer_free = static_cast<int>(integer_after(s, at + 1).value_or(-1));
    }
    if (s.find("T:") != std::string_view::npos) r.temperatures = parse_temperatures(s);
    return r;
  }
  if (starts_with(s, "Resend:") || starts_with(s, "rs ")) {
    r.kind = ReplyKind::resend;
    r.line = integer_after(s, s[0] == 'R' ? 7 : 3);
    if (!r.line) r.kind = ReplyKind::other;
    return r;
  }
  if (s.find("busy:") != std::string_view::npos) {
    r.kind = ReplyKind::busy;
    return r;
  }
  if (s == "wait") {
    r.kind = ReplyKind::wait;
    return r;
  }
  if (s == "start") {
    r.kind = ReplyKind::start;
    return r;
  }
  if (starts_with(s, "Error:") || starts_with(s, "!!")) {
    r.kind = ReplyKind::error;
    for (std::string_view fatal :
         {"halted", "kill()", "Thermal Runaway", "Heating failed", "MINTEMP", "MAXTEMP", "!!"})
      if (s.find(fatal) != std::string_view::npos) r.fatal = true;
    return r;
  }
  if (starts_with(s, "//action:")) {
    r.kind = ReplyKind::action;
    r.name = std::string(trim(s.substr(9)));
    return r;
  }
  if (starts_with(s, "FIRMWARE_NAME:")) {
    r.kind = ReplyKind::firmware;
    const std::size_t end = s.find(" SOURCE_CODE_URL");
    r.name =
        std::string(trim(s.substr(14, end == std::string_view::npos ? std::string_view::npos : end - 14)));
    return r;
  }
  if (starts_with(s, "Cap:")) {
    r.kind = ReplyKind::capability;
    const std::size_t colon = s.find(':', 4);
    r.name = std::string(s.substr(4, colon == std::string_view::npos ? std::string_view::npos : colon - 4));
    r.enabled = colon != std::string_view::npos && s.substr(colon + 1) == "1";
    return r;
  }
  if (starts_with(s, "T:") || starts_with(s, " T:") || starts_with(s, "B:")) {
    r.kind = ReplyKind::temperature;
    r.temperatures = parse_temperatures(s);
    return r;
  }
  return r;
}

}  // namespace salient::protocol::marlin
