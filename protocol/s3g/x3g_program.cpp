#include "protocol/s3g/x3g_program.hpp"

#include <algorithm>

#include "protocol/s3g/x3g_commands.hpp"

namespace salient::protocol::s3g {

std::size_t X3gProgram::first_action_of(std::size_t c) const {
  if (source.empty()) return std::min(c, actions.size());
  return static_cast<std::size_t>(std::lower_bound(source.begin(), source.end(), c) - source.begin());
}

X3gProgram X3gProgram::from_x3g(std::string_view file) {
  X3gProgram p;
  p.actions = split_x3g(file);
  p.commands = p.actions.size();
  return p;
}

std::string X3gProgram::bytes() const {
  std::string out;
  for (const auto& a : actions) out += a;
  return out;
}

}  // namespace salient::protocol::s3g
