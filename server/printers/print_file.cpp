#include "server/printers/print_file.hpp"

#include "protocol/marlin/line_codec.hpp"
#include "protocol/s3g/x3g_translator.hpp"
#include "server/common/domain_error.hpp"

namespace salient::server {

std::shared_ptr<const protocol::Program> printable_program(const std::string& name, const std::string& gcode,
                                                           const PrinterConfig* printer) {
  auto program = std::make_shared<const protocol::Program>(protocol::Program::parse(gcode));
  for (const protocol::Program::Command& c : program->commands())
    if (std::string why = protocol::marlin::unsendable(c.text); !why.empty())
      throw Unprocessable("not_gcode", name + " line " + std::to_string(c.line) + " cannot be sent: " + why);
  if (program->empty())
    throw Unprocessable("no_commands", name + " holds no G-code commands (only comments or blank lines)");
  if (printer && printer->protocol == PrinterProtocol::s3g) {
    const protocol::s3g::Machine* machine = protocol::s3g::find_machine(printer->machine);
    if (!machine) throw Unprocessable("not_x3g", "unknown s3g machine '" + printer->machine + "'");
    const auto skipped = protocol::s3g::translate_gcode(*program, *machine, {}).skipped;
    if (!skipped.empty()) {
      const protocol::s3g::Skipped& s = skipped.front();
      throw Unprocessable("not_x3g", name + " line " + std::to_string(s.line) + " '" +
                                         s.command.substr(0, 40) +
                                         "' cannot be printed over s3g: " + s.reason +
                                         (skipped.size() > 1 ? " (and " + std::to_string(skipped.size() - 1) +
                                                                   " more; was it sliced for this printer?)"
                                                             : ""));
    }
  }
  return program;
}

}  // namespace salient::server
