// Program: a G-code file as a printer link streams it — its commands (comments stripped, blank
// lines skipped), where each one stands in the file (byte offset and 1-based line) and the layer it
// belongs to. The one place G-code text becomes commands: the CLI's print command, the daemon and
// the links read it; a link's session reads the commands from it as they go out rather than
// copying them, so a print holds its file once (shared_ptr: the session and its driver share it).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace salient::protocol {

class Program {
 public:
  struct Command {
    std::string text;        // what goes to the printer (no comment, no surrounding blanks)
    std::size_t offset = 0;  // the byte where its line starts in the file
    std::size_t line = 0;    // 1-based
    std::size_t layer = 0;   // 0-based: counted at each ";LAYER_CHANGE" (PrusaSlicer), or ";LAYER:"
  };

  Program() = default;
  // Lines end at "\n" (a "\r" before it is dropped).
  static Program parse(std::string_view gcode);
  // One line each (console commands, tests); offsets as if they were joined by "\n".
  static Program from_lines(const std::vector<std::string>& lines);

  std::size_t size() const { return commands_.size(); }
  bool empty() const { return commands_.empty(); }
  const Command& operator[](std::size_t i) const { return commands_[i]; }
  const std::vector<Command>& commands() const { return commands_; }
  std::size_t layers() const { return commands_.empty() ? 0 : commands_.back().layer + 1; }

 private:
  template <typename NextLine>
  static Program build(NextLine&& next_line);
  std::vector<Command> commands_;
};

}  // namespace salient::protocol
