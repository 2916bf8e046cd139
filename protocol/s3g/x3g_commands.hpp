// An x3g file is s3g action payloads back to back, unframed. Each action's length follows from its
// id (and, for a few, from a length byte or a terminating NUL): this splits a file into commands,
// and refuses bytes that are not a known action, since the board would stall on an unknown one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace salient::protocol::s3g {

// A byte stream that is not a sequence of known actions: `offset` is where it went wrong.
class X3gError : public std::runtime_error {
 public:
  X3gError(std::size_t offset, const std::string& what);
  std::size_t offset;
};

// The length of the action starting at `bytes[0]` (id included), when the bytes hold all of it;
// nullopt when more bytes are needed. X3gError for an id that is not an action, or a field that
// makes the action longer than a packet holds (32 bytes).
std::optional<std::size_t> action_length(std::string_view bytes);

// The file's actions, in order, each a payload ready to frame. X3gError names the offset of the
// first byte that is not a whole, known action.
std::vector<std::string> split_x3g(std::string_view file);

// The action's name for logs and errors ("queue point", "tool action", …), or nullptr.
const char* action_name(std::uint8_t id);

}  // namespace salient::protocol::s3g
