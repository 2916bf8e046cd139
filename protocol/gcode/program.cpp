#include "protocol/gcode/program.hpp"

#include <optional>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol {
namespace {

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

}  // namespace

// `next_line(line, offset)` gives each line in turn, false at the end; it is walked twice: a file
// with ";LAYER_CHANGE" anywhere counts layers by those (PrusaSlicer also writes ";LAYER:" lines
// that would count twice), any other by ";LAYER:" (Cura).
template <typename NextLine>
Program Program::build(NextLine&& next_line) {
  bool change = false;
  std::string_view line;
  std::size_t offset = 0;
  for (auto walk = next_line(); walk(line, offset);) change = change || starts_with(line, ";LAYER_CHANGE");
  const std::string_view marker = change ? ";LAYER_CHANGE" : ";LAYER:";
  Program p;
  std::size_t layer = 0, number = 0;
  bool started = false;
  for (auto walk = next_line(); walk(line, offset);) {
    ++number;
    if (starts_with(line, marker)) {
      if (started) ++layer;
      started = true;
    }
    std::string command = marlin::strip_comment(line);
    if (!command.empty()) p.commands_.push_back({std::move(command), offset, number, layer});
  }
  return p;
}

Program Program::parse(std::string_view gcode) {
  return build([gcode] {
    return [gcode, start = std::size_t{0}](std::string_view& line, std::size_t& offset) mutable {
      if (start >= gcode.size()) return false;
      std::size_t nl = gcode.find('\n', start);
      if (nl == std::string_view::npos) nl = gcode.size();
      line = gcode.substr(start, nl - start);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      offset = start;
      start = nl + 1;
      return true;
    };
  });
}

Program Program::from_lines(const std::vector<std::string>& lines) {
  return build([&lines] {
    return [&lines, i = std::size_t{0}, at = std::size_t{0}](std::string_view& line,
                                                             std::size_t& offset) mutable {
      if (i >= lines.size()) return false;
      line = lines[i];
      offset = at;
      at += lines[i].size() + 1;
      ++i;
      return true;
    };
  });
}

}  // namespace salient::protocol
