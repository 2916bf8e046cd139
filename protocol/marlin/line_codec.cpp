// Marlin line framing (Marlin's GCodeQueue: a line starting with N must carry "*<xor>").
#include "protocol/marlin/line_codec.hpp"

#include <charconv>
#include <cstdio>

#include "protocol/gcode/command_code.hpp"

namespace salient::protocol::marlin {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n'))
    s.remove_suffix(1);
  return s;
}

}  // namespace

std::uint8_t checksum(std::string_view bytes) {
  std::uint8_t x = 0;
  for (char c : bytes) x ^= static_cast<std::uint8_t>(c);
  return x;
}

std::string strip_comment(std::string_view line) {
  std::string out;
  out.reserve(line.size());
  bool in_paren = false;
  for (char c : line) {
    if (in_paren) {
      if (c == ')') in_paren = false;
      continue;
    }
    if (c == ';' || c == '\n' || c == '\r') break;
    if (c == '(') {
      in_paren = true;
      continue;
    }
    out.push_back(c);
  }
  return std::string(trim(out));
}

std::string numbering_command(std::string_view command) {
  // Marlin's GCodeQueue takes a line as numbered when it starts "N" and a digit or a sign.
  if (command.size() > 1 && (command[0] == 'N' || command[0] == 'n') &&
      ((command[1] >= '0' && command[1] <= '9') || command[1] == '-'))
    return "a line number (" + std::string(command.substr(0, command.find(' '))) +
           "): salientd numbers every line it sends itself; remove the number";
  if (const auto code = command_code(command); code && code->letter == 'M' && code->number == 110)
    return "M110 resets the line numbers, which salientd keeps itself (the printer would ask for the "
           "file again from the start); remove it";
  return {};
}

std::string unsendable(std::string_view command) {
  if (command.size() > kMaxCommandBytes)
    return "a command of " + std::to_string(command.size()) + " bytes (the firmware takes " +
           std::to_string(kMaxCommandBytes) + ")";
  for (std::size_t i = 0; i < command.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(command[i]);
    if (c == '*') return "a '*' inside a command (it would start the checksum)";
    if ((c < 0x20 && c != '\t') || c >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", c);
      return std::string("byte ") + hex + " at column " + std::to_string(i + 1) +
             " (not printable ASCII: is it G-code?)";
    }
  }
  return numbering_command(command);
}

std::optional<Unsendable> find_unsendable(const std::vector<std::string>& lines) {
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string command = strip_comment(lines[i]);
    if (std::string why = unsendable(command); !why.empty()) return Unsendable{i + 1, std::move(why)};
  }
  return std::nullopt;
}

std::optional<double> word_value(std::string_view c, char letter) {
  for (std::size_t at = c.find(' '); at != std::string_view::npos; at = c.find(' ', at + 1)) {
    if (at + 1 >= c.size() || c[at + 1] != letter) continue;
    double v = 0;
    const auto [ptr, ec] = std::from_chars(c.data() + at + 2, c.data() + c.size(), v);
    return ec == std::errc() && ptr != c.data() + at + 2 ? v : 0.0;
  }
  return std::nullopt;
}

std::string frame(std::uint64_t number, std::string_view command) {
  std::string body = "N" + std::to_string(number) + " " + std::string(command);
  return body + "*" + std::to_string(checksum(body));
}

FramedLine parse_frame(std::string_view line, FrameError& error) {
  error = FrameError::none;
  line = trim(line);
  FramedLine out;
  if (line.empty() || line.front() != 'N') {
    out.command = std::string(line);
    return out;
  }
  const std::size_t star = line.rfind('*');
  if (star == std::string_view::npos) {
    error = FrameError::missing_checksum;
    return out;
  }
  unsigned sum = 0;
  const std::string_view digits = line.substr(star + 1);
  auto [p, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), sum);
  if (ec != std::errc() || p != digits.data() + digits.size() || sum > 255 ||
      checksum(line.substr(0, star)) != sum) {
    error = FrameError::bad_checksum;
    return out;
  }
  std::uint64_t number = 0;
  const char* begin = line.data() + 1;
  auto [q, ec2] = std::from_chars(begin, line.data() + star, number);
  if (ec2 != std::errc() || q == begin) {
    error = FrameError::bad_number;
    return out;
  }
  out.number = number;
  out.command = std::string(trim(std::string_view(q, static_cast<std::size_t>(line.data() + star - q))));
  return out;
}

}  // namespace salient::protocol::marlin
