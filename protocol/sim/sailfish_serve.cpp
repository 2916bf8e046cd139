#include "protocol/sim/sailfish_serve.hpp"

#include <poll.h>
#include <sys/prctl.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <stdexcept>

#include "protocol/sim/pseudo_terminal.hpp"

namespace salient::protocol::sim {
namespace {

const char* end_name(SailfishFirmware::State s) {
  switch (s) {
    case SailfishFirmware::State::silent:
      return "silent";
    case SailfishFirmware::State::heater_shutdown:
      return "heater_shutdown";
    default:
      return "stopped";
  }
}

void write_stats(const std::string& path, const SailfishStats& s, const char* end) {
  if (path.empty()) return;
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return;
  std::fprintf(f,
               "{\"executed\": %lld, \"packets_received\": %lld, \"packets_corrupted\": %lld, "
               "\"false_packets\": %lld, "
               "\"crc_errors\": %lld, \"length_errors\": %lld, \"packet_timeouts\": %lld, "
               "\"stray_bytes\": %lld, \"unsupported\": %lld, \"buffer_full_sent\": %lld, "
               "\"storm_refusals\": %lld, \"replies_dropped\": %lld, \"replies_corrupted\": %lld, "
               "\"resets\": %lld, \"bytes_ignored\": %lld, \"end\": \"%s\"}\n",
               s.executed, s.packets_received, s.packets_corrupted, s.false_packets, s.crc_errors,
               s.length_errors, s.packet_timeouts, s.stray_bytes, s.unsupported, s.buffer_full_sent,
               s.storm_refusals, s.replies_dropped, s.replies_corrupted, s.resets, s.bytes_ignored, end);
  std::fclose(f);
}

}  // namespace

int serve_sailfish(SailfishServeOptions& o, const volatile std::sig_atomic_t* stop) {
  o.config.faults = parse_sailfish_faults(o.faults);
  std::FILE* log = nullptr;
  if (!o.log_path.empty() && !(log = std::fopen(o.log_path.c_str(), "w")))
    throw std::runtime_error("--log: cannot write " + o.log_path);
  PseudoTerminal pty;
  if (!o.link_path.empty()) {
    std::error_code ec;
    std::filesystem::remove(o.link_path, ec);
    std::filesystem::create_symlink(pty.device_path(), o.link_path);
  }
  std::printf("%s\n", pty.device_path().c_str());
  std::fflush(stdout);

  // The wire's timing is emulated by sleeping until each packet has arrived: the kernel's default
  // 50 µs timer slack, twice a packet, would cost a few per cent of a 115200-baud link.
  ::prctl(PR_SET_TIMERSLACK, 1UL);
  const auto t0 = std::chrono::steady_clock::now();
  auto now = [&] { return std::chrono::duration_cast<Micros>(std::chrono::steady_clock::now() - t0); };
  SailfishFirmware fw(o.config);
  std::string pending;
  bool log_dirty = false;
  while (!*stop) {
    const Micros t = now();
    fw.advance(t);
    pending += fw.take_output(t);
    if (!pending.empty()) pending.erase(0, pty.write_some(pending));
    for (const std::string& a : fw.take_executed()) {
      if (log) std::fputs(a.c_str(), log), std::fputc('\n', log);
      log_dirty = true;
    }
    const Micros wake = fw.next_wakeup();
    long long wait_us = wake == Micros::max() ? 200000 : std::max<long long>(0, (wake - now()).count());
    wait_us = std::min<long long>(wait_us, 200000);
    pollfd p{pty.descriptor(), static_cast<short>(POLLIN | (pending.empty() ? 0 : POLLOUT)), 0};
    if (log_dirty && wait_us > 0 && ::poll(&p, 1, 0) == 0) {  // idle: make the log readable now
      if (log) std::fflush(log);
      log_dirty = false;
    }
    const timespec ts{static_cast<time_t>(wait_us / 1000000), static_cast<long>(wait_us % 1000000) * 1000};
    if (::ppoll(&p, 1, &ts, nullptr) < 0 && errno != EINTR) throw std::runtime_error("poll failed");
    if (p.revents & POLLIN) fw.receive(pty.read_available(), now());
  }
  pty.close();
  if (log) std::fclose(log);
  if (!o.link_path.empty()) {
    std::error_code ec;
    std::filesystem::remove(o.link_path, ec);
  }
  const char* end = end_name(fw.state());
  write_stats(o.stats_path, fw.stats(), end);
  const SailfishStats& s = fw.stats();
  std::fprintf(stderr,
               "salient-sim: sailfish %s after %lld actions (%lld packets, %lld crc errors, %lld "
               "replies dropped, %lld corrupted, %lld buffer full, %lld resets)\n",
               end, s.executed, s.packets_received, s.crc_errors, s.replies_dropped, s.replies_corrupted,
               s.buffer_full_sent, s.resets);
  return 0;
}

}  // namespace salient::protocol::sim
