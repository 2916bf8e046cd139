// salient-sim --firmware sailfish on a real pseudo-terminal: a real .x3g (written by GPX at test
// time) streamed by a minimal host loop, and by GPX itself (gpx -s, the peer), each proving from
// the simulator's log that the board ran every action exactly once, in order.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/x3g_commands.hpp"

namespace fs = std::filesystem;
namespace s3g = salient::protocol::s3g;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

namespace {

const std::string kProgram = SALIENT_BINARY_DIR "/protocol/salient-sim";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::string hex(const std::string& b) {
  static constexpr char d[] = "0123456789abcdef";
  std::string s;
  for (unsigned char c : b) s += d[c >> 4], s += d[c & 15];
  return s;
}

std::vector<std::string> hexes(const std::vector<std::string>& actions) {
  std::vector<std::string> out;
  for (const auto& a : actions) out.push_back(hex(a));
  return out;
}

pid_t spawn(std::vector<std::string> args, int out_fd, int err_fd) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (out_fd >= 0) ::dup2(out_fd, STDOUT_FILENO);
    if (err_fd >= 0) ::dup2(err_fd, STDERR_FILENO);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());
    std::_Exit(127);
  }
  return pid;
}

int exit_status(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool have_gpx() {
  return std::system("command -v gpx >/dev/null 2>&1") == 0;
}

// A scratch directory with a small G-code file: heat, home, a few hundred moves, end.
struct Scratch {
  fs::path dir;
  Scratch() {
    static int counter = 0;
    dir = fs::temp_directory_path() /
          ("sailfish-sim-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(dir);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  fs::path gcode(int moves) const {
    const fs::path p = dir / "part.gcode";
    std::ofstream g(p);
    g << "M73 P0\nG162 X Y F2500\nG161 Z F1100\nM132 X Y Z A B\nG92 X0 Y0 Z0 A0 B0\n"
         "M104 S220 T0\nM140 S100\nM109 S220 T0\nM190 S100\nG1 Z0.3 F1000\nM106 S255\n";
    double e = 0;
    for (int i = 0; i < moves; ++i) {
      e += 0.2;
      g << "G1 X" << (i % 2 ? 30 : -30) << " Y" << (i % 40) - 20 << " E" << e << " F3000\n";
      if (i == moves / 2) g << "M73 P50\nG4 P20\n";
    }
    g << "M107\nM104 S0\nM140 S0\nM73 P100\nM18\n";
    return p;
  }
  // GPX's x3g for the file; the build name in its first action is `name`.
  std::vector<std::string> x3g(const fs::path& gcode, const std::string& name) const {
    const fs::path out = dir / (name + ".x3g");
    const std::string cmd = "gpx -I -q -m r2x '" + gcode.string() + "' '" + out.string() + "'";
    REQUIRE(std::system(cmd.c_str()) == 0);
    return s3g::split_x3g(slurp(out));
  }
};

// salient-sim --firmware sailfish as a child process, serving until stop().
class Sim {
 public:
  Sim(const fs::path& dir, std::vector<std::string> args) : dir_(dir) {
    args.insert(args.begin(), {kProgram, "--firmware", "sailfish", "--log", (dir / "log").string(), "--stats",
                               (dir / "stats").string()});
    int out[2];
    REQUIRE(::pipe(out) == 0);
    pid_ = spawn(args, out[1], -1);
    ::close(out[1]);
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') device_ += c;
    ::close(out[0]);
    REQUIRE(device_.rfind("/dev/pts/", 0) == 0);
  }
  ~Sim() { stop(); }
  int stop() {
    if (pid_ <= 0) return status_;
    ::kill(pid_, SIGTERM);
    status_ = exit_status(pid_);
    pid_ = -1;
    return status_;
  }
  const std::string& device() const { return device_; }
  std::vector<std::string> log() const { return lines(dir_ / "log"); }
  long long stat(const std::string& key) const {
    const std::string text = slurp(dir_ / "stats");
    const std::size_t at = text.find("\"" + key + "\": ");
    return at == std::string::npos ? -1 : std::stoll(text.substr(at + key.size() + 4));
  }

 private:
  fs::path dir_;
  pid_t pid_ = -1;
  int status_ = -1;
  std::string device_;
};

// The least a host can be: one packet in flight, wait for its reply, on 82 wait and resend.
class MinimalHost {
 public:
  explicit MinimalHost(const std::string& device)
      : fd_(::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC)) {
    REQUIRE(fd_ >= 0);
    termios t{};
    ::tcgetattr(fd_, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(fd_, TCSANOW, &t);
  }
  ~MinimalHost() { ::close(fd_); }

  // The reply's payload; empty after `limit` of silence.
  std::string exchange(const std::string& payload, milliseconds limit = milliseconds(2000)) {
    const std::string f = s3g::frame(payload);
    REQUIRE(::write(fd_, f.data(), f.size()) == ssize_t(f.size()));
    s3g::PacketDecoder d;
    const auto until = Clock::now() + limit;
    while (Clock::now() < until) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      unsigned char buf[64];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      for (ssize_t i = 0; i < n; ++i)
        if (auto r = d.feed(buf[i]); r.payload) return *r.payload;
    }
    return {};
  }
  long long stream(const std::vector<std::string>& actions) {  // the 82s it met
    long long full = 0;
    for (const auto& a : actions) {
      for (;;) {
        const std::string r = exchange(a);
        REQUIRE(!r.empty());
        if (static_cast<unsigned char>(r[0]) == 0x81) break;
        REQUIRE(static_cast<unsigned char>(r[0]) == 0x82);
        ++full;
        std::this_thread::sleep_for(milliseconds(2));
      }
    }
    return full;
  }

 private:
  int fd_;
};

// The log is written when the board is idle; is_finished says when it is.
void wait_until_finished(MinimalHost& host) {
  const auto until = Clock::now() + milliseconds(20000);
  while (Clock::now() < until) {
    const std::string r = host.exchange(std::string(1, '\x0B'));
    if (r.size() == 2 && r[1] == 1) return;
    std::this_thread::sleep_for(milliseconds(10));
  }
  FAIL("the board never finished");
}

}  // namespace

TEST_CASE("salient-sim sailfish runs a GPX x3g streamed by a minimal host exactly once, in order") {
  if (!have_gpx()) {
    MESSAGE("gpx is not installed: skipped");
    return;
  }
  Scratch s;
  const auto actions = s.x3g(s.gcode(300), "part");
  REQUIRE(actions.size() > 300);
  // Moves of ~60 mm at 50 mm/s take 1.2 s; at time scale 0.01, 12 ms: the ring fills at 115200 baud.
  Sim sim(s.dir, {"--time-scale", "0.01", "--heat-time-scale", "0.001", "--baud", "115200", "--faults",
                  "full-storm=0.02,seed=3"});
  MinimalHost host(sim.device());
  const long long full = host.stream(actions);
  wait_until_finished(host);
  CHECK(sim.stop() == 0);
  CHECK(sim.log() == hexes(actions));
  CHECK(sim.stat("executed") == static_cast<long long>(actions.size()));
  CHECK(full > 0);  // the ring was full at times, and the host waited
  CHECK(sim.stat("buffer_full_sent") == full);
  CHECK(sim.stat("storm_refusals") > 0);
  CHECK(sim.stat("storm_refusals") < full);  // and full for real, too
}

TEST_CASE("salient-sim sailfish reset-at: the board goes deaf for a second and comes back empty") {
  Scratch s;
  Sim sim(s.dir, {"--faults", "reset-at=2"});
  MinimalHost host(sim.device());
  const std::string delay = std::string("\x85\0\0\0\0", 5), stats(1, '\x18');
  CHECK(host.exchange(delay) == std::string(1, '\x81'));
  const std::string before = host.exchange(stats);
  REQUIRE(before.size() == 12);
  CHECK(before[4] == 1);                                  // line: one action started
  CHECK(host.exchange(delay) == std::string(1, '\x81'));  // action 2: the reset follows it
  const auto reset = Clock::now();
  CHECK(host.exchange(stats, milliseconds(500)).empty());
  std::this_thread::sleep_until(reset + milliseconds(1100));
  const std::string after = host.exchange(stats);
  REQUIRE(after.size() == 12);
  CHECK(after[4] == 0);
  CHECK(sim.stop() == 0);
  CHECK(sim.log().size() == 2);
  CHECK(sim.stat("resets") == 1);
  CHECK(sim.stat("bytes_ignored") == 4);
}

TEST_CASE("salient-sim sailfish prints a whole file streamed by gpx -s, the peer") {
  if (!have_gpx()) {
    MESSAGE("gpx is not installed: skipped");
    return;
  }
  Scratch s;
  const fs::path gcode = s.gcode(200);
  Sim sim(s.dir, {"--time-scale", "0.01", "--heat-time-scale", "0.001", "--baud", "115200"});
  // GPX names the build after the port's base name ("/dev/pts/3" → "3").
  const std::string name = fs::path(sim.device()).filename().string();
  const auto actions = s.x3g(gcode, name);
  int err[2];
  REQUIRE(::pipe(err) == 0);
  const pid_t gpx = spawn({"gpx", "-s", "-m", "r2x", gcode.string(), sim.device()}, err[1], err[1]);
  ::close(err[1]);
  std::string said;
  char buf[4096];
  for (ssize_t n; (n = ::read(err[0], buf, sizeof buf)) > 0;) said.append(buf, static_cast<std::size_t>(n));
  ::close(err[0]);
  CAPTURE(said);
  CHECK(exit_status(gpx) == 0);
  // GPX returns once the last packet is acked; the board may still be running the ring.
  {
    MinimalHost host(sim.device());
    wait_until_finished(host);
  }
  CHECK(sim.stop() == 0);
  CHECK(sim.log() == hexes(actions));
  CHECK(sim.stat("crc_errors") == 0);
}

TEST_CASE("salient-sim sailfish refuses a Marlin option and a bad fault by name") {
  for (const auto& [args, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--faults", "drop-ok=0.1"}, "--faults: unknown fault 'drop-ok' for sailfish"},
           {{"--faults", "reset-at=-1"}, "--faults: reset-at must be a positive count of actions"},
           {{"--bufsize", "16"}, "--bufsize is a Marlin option"}}) {
    CAPTURE(message);
    std::vector<std::string> argv{kProgram, "--firmware", "sailfish"};
    argv.insert(argv.end(), args.begin(), args.end());
    int out[2];
    REQUIRE(::pipe(out) == 0);
    const pid_t pid = spawn(argv, out[1], out[1]);
    ::close(out[1]);
    std::string said;
    char buf[4096];
    for (ssize_t n; (n = ::read(out[0], buf, sizeof buf)) > 0;) said.append(buf, static_cast<std::size_t>(n));
    ::close(out[0]);
    CHECK(exit_status(pid) == 1);
    CHECK(said.find("salient-sim: error: " + message) != std::string::npos);
  }
  {
    int err[2];
    REQUIRE(::pipe(err) == 0);
    const pid_t marlin = spawn({kProgram, "--quiet-errors"}, err[1], err[1]);
    ::close(err[1]);
    std::string said;
    char b[4096];
    for (ssize_t n; (n = ::read(err[0], b, sizeof b)) > 0;) said.append(b, static_cast<std::size_t>(n));
    ::close(err[0]);
    CHECK(exit_status(marlin) == 1);
    CHECK(said.find("--quiet-errors needs --firmware sailfish") != std::string::npos);
  }
  int out[2];
  REQUIRE(::pipe(out) == 0);
  const pid_t pid = spawn({kProgram, "--help"}, out[1], -1);
  ::close(out[1]);
  std::string help;
  char buf[4096];
  for (ssize_t n; (n = ::read(out[0], buf, sizeof buf)) > 0;) help.append(buf, static_cast<std::size_t>(n));
  ::close(out[0]);
  CHECK(exit_status(pid) == 0);
  for (const char* fault : {"--firmware", "--quiet-errors", "reply-noise=P", "drop-reply=P", "full-storm=P",
                            "reset-at=N", "cancel-at=N", "heater-fault-at=N", "silent-after=N"})
    CHECK(help.find(fault) != std::string::npos);
}
