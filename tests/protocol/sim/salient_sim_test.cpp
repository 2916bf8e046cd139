// The salient-sim executable on a real pseudo-terminal, with a bare host (the device opened raw,
// no session): the faults at a known moment as a host sees them, in wall time, and --faults
// refusing a bad value by name.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "protocol/marlin/line_codec.hpp"

namespace fs = std::filesystem;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

namespace {

const std::string kProgram = SALIENT_BINARY_DIR "/protocol/salient-sim";
const std::string kBanner =
    "start\necho:Marlin 2.1.2 (salient-sim)\necho: Last Updated: 2026-11-22 | Author: (salient-sim)\n";

std::string line(long long n, const std::string& command) {
  return salient::protocol::marlin::frame(static_cast<std::uint64_t>(n), command) + "\n";
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> read_lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

pid_t spawn(std::vector<std::string> args, int out_fd, int err_fd) {
  args.insert(args.begin(), kProgram);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out_fd, STDOUT_FILENO);
    if (err_fd >= 0) ::dup2(err_fd, STDERR_FILENO);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    std::_Exit(127);
  }
  return pid;
}

int exit_status(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// salient-sim as a child process, serving until stop().
class Sim {
 public:
  explicit Sim(std::vector<std::string> args) {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("salient-sim-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(dir_);
    for (const char* opt : {"--log", "--stats"})
      args.push_back(opt), args.push_back((dir_ / (opt + 2)).string());
    int out[2];
    REQUIRE(::pipe(out) == 0);
    pid_ = spawn(args, out[1], -1);
    ::close(out[1]);
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') device_ += c;
    ::close(out[0]);
    REQUIRE(device_.rfind("/dev/pts/", 0) == 0);
  }
  ~Sim() {
    stop();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  int stop() {  // SIGTERM; it writes its log and stats; its exit status
    if (pid_ <= 0) return status_;
    ::kill(pid_, SIGTERM);
    status_ = exit_status(pid_);
    pid_ = -1;
    return status_;
  }
  const std::string& device() const { return device_; }
  std::vector<std::string> log() const { return read_lines(dir_ / "log"); }
  std::string stats() const { return read_file(dir_ / "stats"); }
  long long stat(const std::string& key) const {
    const std::string text = stats();
    const std::size_t at = text.find("\"" + key + "\": ");
    return at == std::string::npos ? -1 : std::stoll(text.substr(at + key.size() + 4));
  }

 private:
  pid_t pid_ = -1;
  int status_ = -1;
  fs::path dir_;
  std::string device_;
};

// A host that opens the device as one opens /dev/ttyACM0, and reads what comes.
class Host {
 public:
  explicit Host(const std::string& device)
      : fd_(::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC)) {
    REQUIRE(fd_ >= 0);
    termios t{};
    ::tcgetattr(fd_, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(fd_, TCSANOW, &t);
  }
  ~Host() { ::close(fd_); }
  Host(const Host&) = delete;
  Host& operator=(const Host&) = delete;

  void send(const std::string& bytes) {
    REQUIRE(::write(fd_, bytes.data(), bytes.size()) == ssize_t(bytes.size()));
  }
  // What arrives until `end` has come (or `limit` has passed); all that arrives within `limit`.
  std::string read_until(const std::string& end, milliseconds limit) { return read(limit, &end); }
  std::string read_for(milliseconds limit) { return read(limit, nullptr); }

 private:
  std::string read(milliseconds limit, const std::string* end) {
    std::string got;
    const auto until = Clock::now() + limit;
    while (!(end && got.find(*end) != std::string::npos) && Clock::now() < until) {
      pollfd p{fd_, POLLIN, 0};
      const auto left = std::chrono::duration_cast<milliseconds>(until - Clock::now()).count();
      if (::poll(&p, 1, static_cast<int>(std::max<long long>(1, left))) <= 0) continue;
      char buf[4096];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n > 0) got.append(buf, static_cast<std::size_t>(n));
    }
    return got;
  }

  int fd_;
};

struct Ended {
  int status;
  std::string out, err;
};

// salient-sim run to its own end (a refused option ends it at once).
Ended run_to_end(const std::vector<std::string>& args) {
  int out[2], err[2];
  REQUIRE(::pipe(out) == 0);
  REQUIRE(::pipe(err) == 0);
  const pid_t pid = spawn(args, out[1], err[1]);
  ::close(out[1]);
  ::close(err[1]);
  auto drain = [](int fd) {
    std::string s;
    char buf[4096];
    for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) s.append(buf, static_cast<std::size_t>(n));
    ::close(fd);
    return s;
  };
  Ended e{0, drain(out[0]), drain(err[0])};
  e.status = exit_status(pid);
  return e;
}

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

TEST_CASE("salient-sim silent-after: the port stays open and nothing answers, silent-for ends it") {
  Sim sim({"--faults", "silent-after=2,silent-for=1.5"});
  Host host(sim.device());
  CHECK(host.read_until(kBanner, milliseconds(2000)) == kBanner);
  host.send("G1 X1\n");
  CHECK(host.read_until("\n", milliseconds(2000)) == "ok\n");
  host.send("G1 X2\n");
  CHECK(host.read_until("\n", milliseconds(2000)) == "ok\n");
  const auto hung = Clock::now();
  host.send("G1 X3\n");
  host.send("M105\n");
  CHECK(host.read_for(milliseconds(800)).empty());
  std::this_thread::sleep_until(hung + milliseconds(1800));
  host.send("M105\n");
  CHECK(host.read_until("\n", milliseconds(2000)).rfind("ok T:", 0) == 0);
  CHECK(sim.stop() == 0);
  CHECK(sim.log() == std::vector<std::string>{"G1 X1", "G1 X2", "M105"});
  CHECK(sim.stat("bytes_ignored") == 11);

  Sim hung_for_good({"--faults", "silent-after=1"});
  Host h(hung_for_good.device());
  h.read_until(kBanner, milliseconds(2000));
  h.send("G1 X1\n");
  CHECK(h.read_until("\n", milliseconds(2000)) == "ok\n");
  h.send("G1 X2\nM105\n");
  CHECK(h.read_for(milliseconds(1000)).empty());
  CHECK(hung_for_good.stop() == 0);  // SIGTERM still ends it
  CHECK(hung_for_good.stats().find("\"end\": \"silent\"") != std::string::npos);
}

TEST_CASE("salient-sim rerequest: an intact line is asked for again, and runs once") {
  Sim sim({"--faults", "rerequest=2"});
  Host host(sim.device());
  host.read_until(kBanner, milliseconds(2000));
  host.send(line(1, "G1 X1"));
  CHECK(host.read_until("ok\n", milliseconds(2000)) == "ok\n");
  host.send(line(2, "G1 X2"));
  CHECK(host.read_until("ok\n", milliseconds(2000)) == "Resend: 2\nok\n");
  host.send(line(2, "G1 X2"));
  CHECK(host.read_until("ok\n", milliseconds(2000)) == "ok\n");
  sim.stop();
  CHECK(sim.log() == std::vector<std::string>{"G1 X1", "G1 X2"});
  CHECK(sim.stat("lines_rerequested") == 1);
}

TEST_CASE("salient-sim busy-at: the command is held, with busy keepalives every 2 s") {
  Sim sim({"--faults", "busy-at=1,busy-for=2.5"});
  Host host(sim.device());
  host.read_until(kBanner, milliseconds(2000));
  const auto t0 = Clock::now();
  host.send("G1 X1\n");
  CHECK(host.read_until("ok\n", milliseconds(5000)) == "echo:busy: processing\nok\n");
  CHECK(seconds_since(t0) > 2.4);
  CHECK(seconds_since(t0) < 4.0);
}

TEST_CASE("salient-sim malformed-ok: the ok arrives with a NUL for its 'k'") {
  Sim sim({"--faults", "malformed-ok=1"});
  Host host(sim.device());
  host.read_until(kBanner, milliseconds(2000));
  host.send("G1 X1\n");
  CHECK(host.read_until("\n", milliseconds(2000)) == std::string("o\0\n", 3));
  host.send("G1 X2\n");
  CHECK(host.read_until("\n", milliseconds(2000)) == "ok\n");
  sim.stop();
  CHECK(sim.stat("oks_malformed") == 1);
}

TEST_CASE("salient-sim reset-on-open: each open reboots it, what the host sends while it boots is lost") {
  Sim sim({"--faults", "reset-on-open,boot-for=0.3"});
  {
    Host host(sim.device());
    const auto opened = Clock::now();
    host.send("M105\n");  // as a host that does not wait for the bootloader
    CHECK(host.read_until(kBanner, milliseconds(3000)) == kBanner);  // once: no banner from before
    CHECK(seconds_since(opened) > 0.25);
    host.send("M105\n");
    CHECK(host.read_until("\n", milliseconds(2000)).rfind("ok T:", 0) == 0);
  }
  Host again(sim.device());
  CHECK(again.read_until(kBanner, milliseconds(3000)) == kBanner);
  sim.stop();
  CHECK(sim.log() == std::vector<std::string>{"M105"});
}

TEST_CASE("salient-sim refuses a bad fault by name, before it offers a device") {
  for (const auto& [spec, message] : std::vector<std::pair<std::string, std::string>>{
           {"silent-for=3", "--faults: silent-for needs silent-after=N"},
           {"busy-for=0", "--faults: busy-for must be a number of seconds"},
           {"malformed-ok=-2", "--faults: malformed-ok must be a positive count of commands"},
           {"reset-on-opne", "--faults: unknown fault 'reset-on-opne'"}}) {
    CAPTURE(spec);
    const Ended e = run_to_end({"--faults", spec});
    CHECK(e.status == 1);
    CHECK(e.out.empty());
    CHECK(e.err.find("salient-sim: error: " + message) != std::string::npos);
  }
  const Ended help = run_to_end({"--help"});
  CHECK(help.status == 0);
  for (const char* fault : {"silent-after=N", "silent-for=S", "rerequest=N", "busy-for=S", "busy-at=N",
                            "malformed-ok=N", "reset-on-open", "boot-for=S"})
    CHECK(help.out.find(fault) != std::string::npos);
}
