// salient-sim: a Marlin-like printer (or, with --firmware sailfish, a Sailfish board speaking
// s3g: sailfish_serve.cpp) behind a pseudo-terminal, for tests, demos and benchmarks.
// Prints the device path (and links it to --link PATH), then serves until SIGINT/SIGTERM, or until
// a disconnect fault pulls the cable. --log FILE gets every executed command, in order.
// The faults are listed in --help (sim_faults.cpp); a bad one is an error naming it, exit status 1.
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "protocol/sim/pseudo_terminal.hpp"
#include "protocol/sim/sailfish_serve.hpp"
#include "protocol/sim/sim_faults.hpp"
#include "protocol/sim/sim_firmware.hpp"

namespace {

volatile sig_atomic_t stop_requested = 0;
void on_signal(int) {
  stop_requested = 1;
}

using salient::protocol::sim::Micros;

struct Options {
  salient::protocol::sim::SimConfig config;
  std::string firmware = "marlin", faults, log_path, link_path, stats_path;
  int bufsize = 4;
  bool quiet_errors = false;  // sailfish only
};

// The options Sailfish shares with Marlin carry over; a Marlin-only one is an error naming it.
int serve_sailfish(const CLI::App& app, const Options& o) {
  for (const char* marlin_only : {"--rx-buffer", "--bufsize", "--planner-blocks", "--advanced-ok",
                                  "--emergency-parser", "--autoreport"})
    if (app.get_option(marlin_only)->count() > 0)
      throw std::invalid_argument(std::string(marlin_only) +
                                  " is a Marlin option (not with --firmware sailfish)");
  salient::protocol::sim::SailfishServeOptions s;
  s.config.error_replies = !o.quiet_errors;
  s.config.baud = o.config.baud;
  s.config.time_scale = o.config.time_scale;
  s.config.heat_time_scale = o.config.heat_time_scale;
  s.faults = o.faults;
  s.log_path = o.log_path;
  s.link_path = o.link_path;
  s.stats_path = o.stats_path;
  return salient::protocol::sim::serve_sailfish(s, &stop_requested);
}

void write_stats(const std::string& path, const salient::protocol::sim::SimStats& s, const char* end) {
  if (path.empty()) return;
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return;
  std::fprintf(
      f,
      "{\"executed\": %lld, \"lines_received\": %lld, \"lines_rejected\": %lld, \"lines_corrupted\": %lld, "
      "\"rx_overflow_bytes\": %lld, \"oks_dropped\": %lld, \"lines_after_halt\": %lld, "
      "\"bytes_ignored\": %lld, \"lines_rerequested\": %lld, \"oks_malformed\": %lld, \"end\": \"%s\"}\n",
      s.executed, s.lines_received, s.lines_rejected, s.lines_corrupted, s.rx_overflow_bytes, s.oks_dropped,
      s.lines_after_halt, s.bytes_ignored, s.lines_rerequested, s.oks_malformed, end);
  std::fclose(f);
}

// The host opened the port: a board that resets on DTR loses what it had sent and not yet
// delivered, and what came in before it noticed. Called before the input is read, so that bytes
// written after the open cannot be taken for ones that came after the reset.
void on_open(salient::protocol::sim::PseudoTerminal& pty, salient::protocol::sim::SimFirmware& fw,
             std::string& pending, Micros now) {
  pty.discard_output();
  pending.clear();
  pty.read_available();
  fw.port_opened(now);
}

int serve(Options& o) {
  using namespace salient::protocol::sim;
  o.config.bufsize = static_cast<std::size_t>(o.bufsize);
  o.config.faults = parse_faults(o.faults);
  std::FILE* log = nullptr;
  if (!o.log_path.empty() && !(log = std::fopen(o.log_path.c_str(), "w")))
    throw std::runtime_error("--log: cannot write " + o.log_path);
  PseudoTerminal pty;
  if (o.config.faults.reset_on_open) pty.watch_opens();
  if (!o.link_path.empty()) {
    std::error_code ec;
    std::filesystem::remove(o.link_path, ec);
    std::filesystem::create_symlink(pty.device_path(), o.link_path);
  }
  std::printf("%s\n", pty.device_path().c_str());
  std::fflush(stdout);

  const auto t0 = std::chrono::steady_clock::now();
  auto now = [&] { return std::chrono::duration_cast<Micros>(std::chrono::steady_clock::now() - t0); };
  SimFirmware fw(o.config);
  // With reset-on-open it boots as the host opens the port: no one could hear a power-on banner.
  if (!o.config.faults.reset_on_open) fw.boot(now());
  std::string pending;
  bool log_dirty = false;
  const char* end = "stopped";
  while (!stop_requested) {
    Micros t = now();
    fw.advance(t);
    pending += fw.take_output(t);
    if (!pending.empty()) pending.erase(0, pty.write_some(pending));
    for (const std::string& c : fw.take_executed()) {
      if (log) std::fputs(c.c_str(), log), std::fputc('\n', log);
      log_dirty = true;
    }
    if (fw.state() == SimFirmware::State::disconnected) {
      end = "disconnected";
      break;
    }
    const Micros wake = fw.next_wakeup();
    long long wait_us = wake == Micros::max() ? 200000 : std::max<long long>(0, (wake - now()).count());
    wait_us = std::min<long long>(wait_us, 200000);
    pollfd p[2] = {{pty.descriptor(), static_cast<short>(POLLIN | (pending.empty() ? 0 : POLLOUT)), 0},
                   {pty.watch_descriptor(), POLLIN, 0}};
    const nfds_t fds = pty.watch_descriptor() >= 0 ? 2 : 1;
    if (log_dirty && wait_us > 0 && ::poll(p, fds, 0) == 0) {  // idle: make the log readable now
      if (log) std::fflush(log);
      log_dirty = false;
    }
    const timespec ts{static_cast<time_t>(wait_us / 1000000), static_cast<long>(wait_us % 1000000) * 1000};
    if (::ppoll(p, fds, &ts, nullptr) < 0 && errno != EINTR) throw std::runtime_error("poll failed");
    if ((p[1].revents & POLLIN) && pty.take_opens() > 0) on_open(pty, fw, pending, now());
    if (p[0].revents & POLLIN) fw.receive(pty.read_available(), now());
  }
  pty.close();
  if (log) std::fclose(log);
  if (!o.link_path.empty()) {
    std::error_code ec;
    std::filesystem::remove(o.link_path, ec);
  }
  if (fw.state() == SimFirmware::State::halted) end = "halted";
  if (fw.state() == SimFirmware::State::silent) end = "silent";
  write_stats(o.stats_path, fw.stats(), end);
  std::fprintf(
      stderr, "salient-sim: %s after %lld commands (%lld lines rejected, %lld corrupted, %lld oks dropped)\n",
      end, fw.stats().executed, fw.stats().lines_rejected, fw.stats().lines_corrupted,
      fw.stats().oks_dropped);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"salient-sim: a simulated Marlin printer (or Sailfish board) on a pseudo-terminal"};
  Options o;
  auto& c = o.config;
  app.add_option("--firmware", o.firmware, "the board: marlin (G-code lines) or sailfish (s3g packets)")
      ->check(CLI::IsMember({"marlin", "sailfish"}))
      ->capture_default_str();
  app.add_flag("--quiet-errors", o.quiet_errors,
               "sailfish: no 80/83/84/8C replies, as Sailfish 7.7 really does (the host times out)");
  app.add_option("--rx-buffer", c.rx_buffer_bytes, "receive buffer in bytes (Marlin RX_BUFFER_SIZE)")
      ->capture_default_str();
  app.add_option("--bufsize", o.bufsize, "command queue slots (BUFSIZE)")
      ->check(CLI::IsMember({4, 16}))
      ->capture_default_str();
  app.add_option("--planner-blocks", c.planner_blocks, "planner moves (BLOCK_BUFFER_SIZE)")
      ->capture_default_str();
  app.add_flag("--advanced-ok", c.advanced_ok, "answer \"ok N<line> P<planner> B<queue>\"");
  app.add_flag("--emergency-parser", c.emergency_parser, "act on M108/M112/M410 as they arrive");
  app.add_flag("--autoreport", c.autoreport, "support M155 temperature auto-report");
  app.add_option("--baud", c.baud, "emulated line speed in bits per second (0: no limit)")
      ->capture_default_str();
  app.add_option("--time-scale", c.time_scale, "wall seconds per printer second for moves (0: instant)")
      ->capture_default_str();
  app.add_option("--heat-time-scale", c.heat_time_scale, "the same for heating (default: --time-scale)");
  app.add_option(
      "--faults", o.faults,
      "what goes wrong, e.g. noise=0.02,drop-ok=0.01,silent-after=500,silent-for=30 (listed below)");
  app.add_option("--log", o.log_path,
                 "write every executed command to FILE (sailfish: each action's payload in hex)");
  app.add_option("--link", o.link_path, "make PATH a symbolic link to the device");
  app.add_option("--stats", o.stats_path, "write counters as JSON to FILE on exit");
  app.footer(std::string(salient::protocol::sim::faults_help()) + "\n" +
             std::string(salient::protocol::sim::sailfish_faults_help()));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (o.quiet_errors && o.firmware != "sailfish") {
    std::fprintf(stderr, "salient-sim: error: --quiet-errors needs --firmware sailfish\n");
    return 1;
  }
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  try {
    return o.firmware == "sailfish" ? serve_sailfish(app, o) : serve(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "salient-sim: error: %s\n", e.what());
    return 1;
  }
}
