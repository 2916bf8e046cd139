#include "server/printers/print_file.hpp"

#include "protocol/marlin/line_codec.hpp"
#include "server/common/domain_error.hpp"

namespace salient::server {

std::shared_ptr<const protocol::Program> printable_program(const std::string& name,
                                                           const std::string& gcode) {
  auto program = std::make_shared<const protocol::Program>(protocol::Program::parse(gcode));
  for (const protocol::Program::Command& c : program->commands())
    if (std::string why = protocol::marlin::unsendable(c.text); !why.empty())
      throw Unprocessable("not_gcode", name + " line " + std::to_string(c.line) + " cannot be sent: " + why);
  if (program->empty())
    throw Unprocessable("no_commands", name + " holds no G-code commands (only comments or blank lines)");
  return program;
}

}  // namespace salient::server
