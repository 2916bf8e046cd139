// `salient print FILE.gcode --port DEV | --tcp HOST:PORT`: streams G-code to a Marlin printer,
// with a progress line (commands, layer, temperatures, time left) and a safe Ctrl-C: the first
// cancels (heaters off, head lifted), a second one sends M112. `--protocol s3g` streams an .x3g
// file (or G-code through the translator) to a MakerBot/Sailfish board the same way.
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "core/gcode/time_estimator.hpp"
#include "protocol/gcode/program.hpp"
#include "protocol/s3g/machine.hpp"
#include "protocol/s3g/x3g_commands.hpp"
#include "protocol/s3g/x3g_program.hpp"
#include "protocol/s3g/x3g_translator.hpp"
#include "protocol/serial/marlin_link.hpp"
#include "protocol/serial/s3g_link.hpp"

namespace salient::cli {
namespace {

namespace marlin = protocol::marlin;
namespace serial = protocol::serial;

volatile sig_atomic_t interrupts = 0;
void on_interrupt(int) {
  interrupts = interrupts + 1;
}

struct PrintOptions {
  std::string file, port, tcp, protocol = "marlin", machine = "r2x";
  unsigned baud = 250000;
  bool reset = false, json = false, quiet = false;
  std::size_t resume_from = 0;
  double timeout = 10, silence = 10;
  std::size_t rx_buffer = 128;
};

// What the progress line shows; written by the link's thread, read by the main one.
struct Progress {
  std::mutex mutex;
  std::size_t done = 0;
  std::optional<double> hotend, hotend_target, bed, bed_target;
  std::string last_error;
  std::size_t resends = 0;
};

std::string hms(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

std::string temperature(const std::optional<double>& t, const std::optional<double>& target) {
  if (!t) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f/%.0f°C", *t, target.value_or(0));
  return buf;
}

// The progress line of a G-code print: commands, layer, temperatures and the time left from the
// estimate of the layers to go.
void draw_gcode_progress(const protocol::Program& commands, const core::GcodeEstimate& estimate,
                         const Progress& progress) {
  const std::size_t total = commands.size(), layers = commands.layers();
  const std::size_t done = std::min(progress.done, total);
  const std::size_t layer = done < total ? commands[done].layer : (layers ? layers - 1 : 0);
  double left = 0;
  for (std::size_t l = layer + 1; l < estimate.layer_seconds.size(); ++l) left += estimate.layer_seconds[l];
  if (layer < estimate.layer_seconds.size()) {
    std::size_t first = done, last = done;
    while (first > 0 && commands[first - 1].layer == layer) --first;
    while (last < total && commands[last].layer == layer) ++last;
    const double share = last > first ? double(last - done) / double(last - first) : 0;
    left += estimate.layer_seconds[layer] * share;
  }
  const int width = 30;
  const int filled = total ? static_cast<int>(width * done / total) : width;
  std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %zu/%zu  layer %zu/%zu  hotend %s  bed %s  left %s ", filled,
               "##############################", width - filled, "",
               total ? 100.0 * double(done) / double(total) : 100.0, done, total, layer + 1, layers,
               temperature(progress.hotend, progress.hotend_target).c_str(),
               temperature(progress.bed, progress.bed_target).c_str(), hms(left).c_str());
}

std::string known_machines() {
  std::string list;
  for (const std::string& id : protocol::s3g::machine_ids()) list += (list.empty() ? "" : ", ") + id;
  return list;
}

bool is_x3g(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".x3g" || ext == ".s3g";
}

// Runs `print` on a worker thread while this one draws the progress line and turns Ctrl-C into
// a cancel (the first) or an emergency stop (the next).
serial::PrintResult drive(protocol::PrinterLink& link, bool tty, Progress& progress,
                          const std::function<serial::PrintResult(const protocol::LinkEventFn&)>& print,
                          const std::function<void()>& draw) {
  serial::PrintResult result;
  std::atomic<bool> over{false};
  struct sigaction sa {
  }, old_int{}, old_term{};
  sa.sa_handler = on_interrupt;
  interrupts = 0;
  ::sigaction(SIGINT, &sa, &old_int);
  ::sigaction(SIGTERM, &sa, &old_term);
  std::thread worker([&] {
    result = print([&](const protocol::LinkEvent& e) {
      std::lock_guard lock(progress.mutex);
      using K = protocol::LinkEvent::Kind;
      if (e.kind == K::progress) progress.done = e.done;
      if (e.kind == K::resend) ++progress.resends;
      if (e.kind == K::error) progress.last_error = e.text;
      if (e.kind == K::temperatures) {
        if (e.hotend) progress.hotend = e.hotend, progress.hotend_target = e.hotend_target;
        if (e.bed) progress.bed = e.bed, progress.bed_target = e.bed_target;
      }
    });
    over = true;
  });
  int handled = 0;
  while (!over) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (interrupts > handled) {
      ++handled;
      if (handled == 1) {
        if (tty)
          std::fprintf(stderr,
                       "\nsalient: cancelling: heaters off, head lifted (Ctrl-C again: emergency stop)\n");
        link.cancel();
      } else {
        link.emergency_stop();
      }
    }
    if (!tty) continue;
    std::lock_guard lock(progress.mutex);
    draw();
    std::fflush(stderr);
  }
  worker.join();
  ::sigaction(SIGINT, &old_int, nullptr);
  ::sigaction(SIGTERM, &old_term, nullptr);
  if (tty) std::fprintf(stderr, "\n");
  return result;
}

// The result as the user reads it (or JSON), and the exit status: 0 finished, 130 cancelled,
// 4 disconnected, 1 failed.
int report(const PrintOptions& o, const std::string& name, const serial::PrintResult& result,
           const std::string& firmware, const char* unit, const std::string& resume_args) {
  using protocol::PrintEnd;
  const char* state = result.disconnected                 ? "disconnected"
                      : result.end == PrintEnd::finished  ? "finished"
                      : result.end == PrintEnd::cancelled ? "cancelled"
                                                          : "failed";
  if (o.json) {
    const nlohmann::json j = {{"file", name},
                              {"state", state},
                              {"confirmed", result.confirmed},
                              {"total", result.total},
                              {"reason", result.reason},
                              {"lines_resent", result.lines_resent},
                              {"pokes", result.pokes},
                              {"seconds", result.seconds},
                              {"firmware", firmware}};
    std::printf("%s\n", j.dump(2).c_str());
  } else if (result.end == PrintEnd::finished) {
    std::printf("%s: printed %zu commands in %.1f s (%.0f %s/s), %zu %s resent\n", name.c_str(), result.total,
                result.seconds, double(result.total - o.resume_from) / std::max(result.seconds, 1e-9), unit,
                result.lines_resent, unit);
  } else {
    std::printf("%s: %s after %zu of %zu commands were confirmed: %s\n", name.c_str(), state,
                result.confirmed, result.total, result.reason.c_str());
    if (result.disconnected || result.end == PrintEnd::failed)
      std::printf("to resume: salient print %s %s %s%s --resume-from %zu\n", o.file.c_str(),
                  o.tcp.empty() ? "--port" : "--tcp", (o.tcp.empty() ? o.port : o.tcp).c_str(),
                  resume_args.c_str(), result.confirmed);
  }
  if (result.end == PrintEnd::finished) return 0;
  if (result.end == PrintEnd::cancelled) return 130;
  return result.disconnected ? 4 : 1;
}

// `--protocol s3g`: an .x3g file as it is, or G-code through the translator.
int print_s3g(const PrintOptions& o, unsigned baud, bool timeout_given) {
  namespace s3g = protocol::s3g;
  const std::string name = std::filesystem::path(o.file).filename().string();
  std::ifstream in(o.file, std::ios::binary);
  if (!in) throw core::InputError(name, {}, "cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  std::string bytes = std::move(text).str();
  serial::S3gLinkConfig config;
  if (timeout_given) config.session.reply_timeout = s3g::Millis(static_cast<long long>(o.timeout * 1000));
  config.session.silence_limit = s3g::Millis(static_cast<long long>(o.silence * 1000));
  std::shared_ptr<const s3g::X3gProgram> program;
  std::shared_ptr<const protocol::Program> gcode;  // a G-code file: its layers drive the progress line
  core::GcodeEstimate estimate;
  if (is_x3g(o.file)) {
    try {
      program = std::make_shared<const s3g::X3gProgram>(s3g::X3gProgram::from_x3g(bytes));
    } catch (const s3g::X3gError& e) {
      throw core::InputError(name, {}, std::string("not an x3g file: ") + e.what());
    }
  } else {
    const s3g::Machine* machine = s3g::find_machine(o.machine);
    if (!machine)
      throw core::InputError("--machine", {},
                             "unknown machine '" + o.machine + "' (known: " + known_machines() + ")");
    estimate = core::estimate_gcode(bytes, name);
    gcode = std::make_shared<const protocol::Program>(protocol::Program::parse(bytes));
    s3g::TranslateOptions options;
    options.build_name = s3g::build_name_for(o.file);
    options.source = bytes;  // comments: M70/M71 messages, as gpx reads them
    s3g::Translation t = s3g::translate_gcode(*gcode, *machine, options);
    if (!o.quiet)
      for (const auto& skip : t.skipped)
        std::fprintf(stderr, "salient: warning: %s:%zu: skipped '%s': %s\n", name.c_str(), skip.line,
                     skip.command.c_str(), skip.reason.c_str());
    program = std::make_shared<const s3g::X3gProgram>(std::move(t.program));
  }
  std::string().swap(bytes);
  if (o.resume_from > program->commands)
    throw core::InputError("--resume-from", {},
                           "the file has only " + std::to_string(program->commands) + " commands");

  auto transport =
      o.tcp.empty() ? serial::open_serial({o.port, baud, true, o.reset}) : serial::open_tcp(o.tcp);
  serial::S3gLink link(std::move(transport), config);
  const serial::FirmwareInfo fw = link.handshake();
  const bool tty = !o.quiet && !o.json && ::isatty(STDERR_FILENO);
  if (!o.quiet && !o.json)
    std::fprintf(stderr, "salient: %s: %s\n", o.tcp.empty() ? o.port.c_str() : o.tcp.c_str(),
                 fw.name.c_str());
  Progress progress;
  progress.done = o.resume_from;
  const auto t0 = std::chrono::steady_clock::now();
  const serial::PrintResult result = drive(
      link, tty, progress,
      [&](const protocol::LinkEventFn& on_event) { return link.print_x3g(program, on_event, o.resume_from); },
      [&] {
        if (gcode) return draw_gcode_progress(*gcode, estimate, progress);
        // No layers in an x3g file: the time left is extrapolated from the rate so far.
        const std::size_t total = program->commands, done = std::min(progress.done, total);
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const std::size_t fresh = done > o.resume_from ? done - o.resume_from : 0;
        const std::string left = fresh ? hms(elapsed * double(total - done) / double(fresh)) : "-";
        const int width = 30;
        const int filled = total ? static_cast<int>(width * done / total) : width;
        std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %zu/%zu  hotend %s  bed %s  left %s ", filled,
                     "##############################", width - filled, "",
                     total ? 100.0 * double(done) / double(total) : 100.0, done, total,
                     temperature(progress.hotend, progress.hotend_target).c_str(),
                     temperature(progress.bed, progress.bed_target).c_str(), left.c_str());
      });
  std::string resume_args = " --protocol s3g";
  if (baud != 115200) resume_args += " --baud " + std::to_string(baud);
  return report(o, name, result, fw.name, "packets", resume_args);
}

}  // namespace

void add_print_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<PrintOptions>();
  CLI::App* cmd =
      app.add_subcommand("print",
                         "Stream a G-code file to a Marlin printer (or an .x3g file to a MakerBot/Sailfish "
                         "board) over USB serial or TCP");
  cmd->add_option("FILE", o->file, "G-code file (.x3g with --protocol s3g)")->required();
  auto* port =
      cmd->add_option("--port", o->port, "Serial device (/dev/ttyACM0, or salient-sim's pseudo-terminal)");
  auto* tcp = cmd->add_option("--tcp", o->tcp, "HOST:PORT of a serial-over-TCP bridge (ser2net)");
  port->excludes(tcp);
  auto* baud =
      cmd->add_option("--baud", o->baud, "Line speed (s3g: 115200 unless given)")->capture_default_str();
  cmd->add_option("--protocol", o->protocol, "marlin (G-code lines) or s3g (MakerBot/Sailfish packets)")
      ->capture_default_str()
      ->check(CLI::IsMember({"marlin", "s3g"}));
  cmd->add_option("--machine", o->machine, "s3g: the machine a G-code file is translated for (GPX's ids)")
      ->capture_default_str();
  cmd->add_flag("--reset", o->reset, "Pulse DTR first (boards with auto-reset reboot)");
  cmd->add_option("--resume-from", o->resume_from,
                  "Skip the first N commands (the count confirmed when a print was cut off) after restoring "
                  "temperatures, modes and position");
  auto* timeout =
      cmd->add_option(
             "--timeout", o->timeout,
             "Longest wait for a reply before poking the printer (the wait adapts to the replies seen, "
             "from 0.25 s; "
             "homing and heating wait this long)")
          ->capture_default_str()
          ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--silence", o->silence,
                  "Seconds of silence after a poke before the print fails (the printer stopped answering)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  cmd->add_option("--rx-buffer", o->rx_buffer,
                  "The firmware's receive buffer in bytes (send-ahead never exceeds it)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print the result as JSON");
  cmd->add_flag("--quiet", o->quiet, "No progress line");
  cmd->callback([o, &action, baud, timeout] {
    const bool baud_given = baud->count() > 0, timeout_given = timeout->count() > 0;
    action = [o, baud_given, timeout_given]() -> int {
      if (o->port.empty() && o->tcp.empty())
        throw core::InputError("--port", {}, "say where the printer is: --port DEV or --tcp HOST:PORT");
      if (o->protocol == "s3g") return print_s3g(*o, baud_given ? o->baud : 115200, timeout_given);
      const std::string name = std::filesystem::path(o->file).filename().string();
      std::ifstream in(o->file, std::ios::binary);
      if (!in) throw core::InputError(name, {}, "cannot open for reading");
      std::ostringstream text;
      text << in.rdbuf();
      std::string gcode = std::move(text).str();
      const core::GcodeEstimate estimate = core::estimate_gcode(gcode, name);
      const auto program = std::make_shared<const protocol::Program>(protocol::Program::parse(gcode));
      std::string().swap(gcode);  // the program is what stays in memory while it prints
      const protocol::Program& commands = *program;
      if (o->resume_from > commands.size())
        throw core::InputError("--resume-from", {},
                               "the file has only " + std::to_string(commands.size()) + " commands");

      serial::LinkConfig config;
      config.session.reply_timeout = marlin::Millis(static_cast<long long>(o->timeout * 1000));
      config.session.silence_limit = marlin::Millis(static_cast<long long>(o->silence * 1000));
      config.session.rx_buffer_bytes = o->rx_buffer;
      auto transport =
          o->tcp.empty() ? serial::open_serial({o->port, o->baud, true, o->reset}) : serial::open_tcp(o->tcp);
      serial::MarlinLink link(std::move(transport), config);
      const serial::FirmwareInfo fw = link.handshake();
      const bool tty = !o->quiet && !o->json && ::isatty(STDERR_FILENO);
      if (!o->quiet && !o->json)
        std::fprintf(stderr, "salient: %s: %s%s\n", o->tcp.empty() ? o->port.c_str() : o->tcp.c_str(),
                     fw.name.empty() ? "unnamed firmware" : fw.name.c_str(),
                     fw.emergency_parser ? ", emergency parser" : "");

      Progress progress;
      progress.done = o->resume_from;
      const serial::PrintResult result = drive(
          link, tty, progress,
          [&](const protocol::LinkEventFn& on_event) {
            return link.print(program, on_event, o->resume_from);
          },
          [&] { draw_gcode_progress(commands, estimate, progress); });
      return report(*o, name, result, fw.name, "lines", "");
    };
  });
}

}  // namespace salient::cli
