// `salient export-x3g FILE.gcode -o FILE.x3g [--machine r2x]`: G-code to the x3g a MakerBot
// Replicator (Sailfish) plays from its SD card, byte for byte what `gpx -I -q -m r2x` writes.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "protocol/gcode/program.hpp"
#include "protocol/s3g/machine.hpp"
#include "protocol/s3g/x3g_translator.hpp"

namespace salient::cli {
namespace {

struct ExportX3gOptions {
  std::string input, output, machine = "r2x";
};

std::string known_machines() {
  std::string list;
  for (const std::string& id : protocol::s3g::machine_ids()) list += (list.empty() ? "" : ", ") + id;
  return list;
}

int export_x3g(const ExportX3gOptions& o) {
  const protocol::s3g::Machine* machine = protocol::s3g::find_machine(o.machine);
  if (!machine)
    throw core::InputError("--machine", {},
                           "unknown machine '" + o.machine + "' (known: " + known_machines() + ")");
  const std::string in_name = std::filesystem::path(o.input).filename().string();
  std::ifstream in(o.input, std::ios::binary);
  if (!in || std::filesystem::is_directory(o.input))
    throw core::InputError(in_name, {}, "cannot open for reading");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw core::InputError(in_name, {}, "cannot read");

  protocol::s3g::TranslateOptions options;
  options.build_name = protocol::s3g::build_name_for(o.output);
  options.source = text;  // comments: M70/M71 messages, as gpx reads them
  const auto t = protocol::s3g::translate_gcode(protocol::Program::parse(text), *machine, options);
  for (const auto& s : t.skipped)
    std::fprintf(stderr, "salient: warning: %s:%zu: skipped '%s': %s\n", in_name.c_str(), s.line,
                 s.command.c_str(), s.reason.c_str());

  // Written beside the target and renamed over it: never a half-written .x3g.
  const std::string bytes = t.program.bytes();
  const std::string temp = o.output + ".part";
  std::ofstream out(temp, std::ios::binary | std::ios::trunc);
  if (out) out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (out) out.close();
  std::error_code ec;
  if (out) std::filesystem::rename(temp, o.output, ec);
  if (!out || ec) {
    std::filesystem::remove(temp, ec);
    throw core::InputError(o.output, {}, "cannot write");
  }
  std::printf("%s: %zu actions, %zu bytes, %zu skipped, for the %s -> %s\n", in_name.c_str(),
              t.program.actions.size(), bytes.size(), t.skipped.size(), machine->name.c_str(),
              o.output.c_str());
  return 0;
}

}  // namespace

void add_export_x3g_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<ExportX3gOptions>();
  CLI::App* cmd =
      app.add_subcommand("export-x3g", "Convert G-code to .x3g for a MakerBot Replicator (as gpx does)");
  cmd->add_option("GCODE", o->input, "G-code file to convert")->required();
  cmd->add_option("-o,--output", o->output, "x3g file to write (its base name is the build's name)")
      ->required();
  cmd->add_option("--machine", o->machine, "gpx machine: " + known_machines())->capture_default_str();
  cmd->callback([o, &action] { action = [o] { return export_x3g(*o); }; });
}

}  // namespace salient::cli
