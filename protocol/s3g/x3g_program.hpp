// X3gProgram: what an s3g link streams — action payloads in order (each ready to frame), and for
// each the G-code command it came from, so that progress and resume count in the same commands as
// a Marlin print of the same file. Made by translate_gcode (x3g_translator.hpp) or from an .x3g
// file (from_x3g: then action i is command i).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace salient::protocol::s3g {

struct X3gProgram {
  std::vector<std::string> actions;
  // source[i]: the index of the command (Program's, 0-based) that action i came from;
  // non-decreasing. Empty for an .x3g file.
  std::vector<std::size_t> source;
  std::size_t commands = 0;  // how many commands progress counts (Program::size(), or actions.size())

  // The command that action i belongs to.
  std::size_t command_of(std::size_t i) const { return source.empty() ? i : source[i]; }
  // The first action of command `c` or after it (actions.size() when none): where a print that
  // has `c` commands done resumes.
  std::size_t first_action_of(std::size_t c) const;
  // An .x3g file's bytes (split_x3g; X3gError on bytes that are not whole, known actions).
  static X3gProgram from_x3g(std::string_view file);
  // The payloads back to back: the .x3g file.
  std::string bytes() const;
};

}  // namespace salient::protocol::s3g
