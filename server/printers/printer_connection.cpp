#include "server/printers/printer_connection.hpp"

#include <algorithm>

#include "protocol/s3g/x3g_translator.hpp"
#include "protocol/serial/marlin_link.hpp"
#include "protocol/serial/s3g_link.hpp"
#include "server/printers/terminal_tap.hpp"

namespace salient::server {

PrinterConnection open_printer_connection(const PrinterConfig& config, TerminalHooks terminal) {
  namespace serial = protocol::serial;
  PrinterConnection c;
  std::unique_ptr<serial::Transport> transport;
  switch (config.kind) {
    case PrinterKind::sim:
      c.sim = std::make_unique<SimProcess>(find_sim_program(), split_args(config.sim_args));
      c.device = c.sim->device();
      transport = serial::open_serial({c.device, config.baud});
      break;
    case PrinterKind::serial:
      c.device = config.port;
      transport = serial::open_serial({c.device, config.baud});
      break;
    case PrinterKind::tcp:
      c.device = config.port;
      transport = serial::open_tcp(config.port);
      break;
  }
  auto wanted = std::move(terminal.wanted);
  auto line = std::move(terminal.line);
  auto tap = std::make_unique<TerminalTap>(
      std::move(transport), [wanted = std::move(wanted)] { return wanted && wanted(); },
      [line = std::move(line)](bool sent, std::string_view l) {
        if (line) line(sent, l);
      },
      config.protocol == PrinterProtocol::s3g);
  switch (config.protocol) {
    case PrinterProtocol::marlin:
      c.link = std::make_unique<serial::MarlinLink>(std::move(tap));
      break;
    case PrinterProtocol::s3g: {
      const protocol::s3g::Machine* machine = protocol::s3g::find_machine(config.machine);
      if (!machine) throw std::runtime_error("unknown s3g machine '" + config.machine + "'");
      serial::S3gLinkConfig s3g;
      // The G-code of a job or a file becomes x3g on the way; a print of a file with a command the
      // translator cannot handle was refused before it started (printable_program).
      // A file that starts a build (M73 P0 or M136, as slicers write) gets the board's build
      // notifications, as gpx writes them; console commands do not: they are not a build.
      s3g.translate = [machine, name = config.id](const protocol::Program& program) {
        const bool build = std::any_of(
            program.commands().begin(), program.commands().end(),
            [](const auto& c) { return c.text.rfind("M73 ", 0) == 0 || c.text.rfind("M136", 0) == 0; });
        return protocol::s3g::translate_gcode(program, *machine,
                                              {.build_name = name, .build_start = build, .build_end = build})
            .program;
      };
      c.link = std::make_unique<serial::S3gLink>(std::move(tap), std::move(s3g));
      break;
    }
  }
  return c;
}

}  // namespace salient::server
