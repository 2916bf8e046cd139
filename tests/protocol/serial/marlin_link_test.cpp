// The printer link end to end: MarlinLink over our Asio serial transport, to the salient-sim
// executable on a real pseudo-terminal. For a G-code file of more than 50,000 lines, under each
// fault and all at once, the simulator's log of executed commands must be the file's commands,
// exactly: none lost, none doubled (besides the host's own M115, M110 and counted M105 pokes).
#include "protocol/serial/marlin_link.hpp"

#include <arpa/inet.h>
#include <doctest/doctest.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "protocol/marlin/line_codec.hpp"
#include "protocol/marlin/resume_prelude.hpp"
#include "protocol/sim/sim_firmware.hpp"

namespace fs = std::filesystem;
using namespace salient::protocol;
using std::chrono::milliseconds;

namespace {

// A print as a slicer writes it: heat-up, then layers of perimeters and infill.
std::vector<std::string> make_gcode(std::size_t moves) {
  std::vector<std::string> g = {"; generated for the link tests",
                                "M140 S60",
                                "M104 S210",
                                "G28 ; home all axes",
                                "M190 S60",
                                "M109 S210",
                                "G90",
                                "M83",
                                "G92 E0",
                                ""};
  char buf[96];
  for (std::size_t i = 0, layer = 0; i < moves; ++i) {
    if (i % 500 == 0) {
      g.push_back(";LAYER_CHANGE");
      std::snprintf(buf, sizeof buf, "G1 Z%.2f F600", 0.2 * double(++layer));
      g.push_back(buf);
    }
    const double a = double(i % 500) * 0.0125;
    std::snprintf(buf, sizeof buf, "G1 X%.3f Y%.3f E%.5f%s", 100 + 30 * std::cos(a), 100 + 30 * std::sin(a),
                  0.02 + 1e-5 * double(i % 97), i % 50 == 0 ? " F1800 ; perimeter" : "");
    g.push_back(buf);
  }
  g.push_back("M104 S0");
  g.push_back("M140 S0");
  g.push_back("M84");
  return g;
}

std::vector<std::string> commands_of(const std::vector<std::string>& gcode, std::size_t from = 0) {
  std::vector<std::string> out;
  std::size_t n = 0;
  for (const std::string& l : gcode) {
    std::string c = marlin::strip_comment(l);
    if (!c.empty() && n++ >= from) out.push_back(std::move(c));
  }
  return out;
}

std::vector<std::string> read_lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

long long stat_of(const fs::path& stats, const std::string& key) {
  std::ifstream in(stats);
  std::stringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  const std::size_t at = text.find("\"" + key + "\": ");
  return at == std::string::npos ? -1 : std::stoll(text.substr(at + key.size() + 4));
}

// salient-sim as a child process, on its own pseudo-terminal.
class Simulator {
 public:
  explicit Simulator(std::vector<std::string> args) {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("salient-link-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(dir_);
    args.insert(args.begin(), SALIENT_BINARY_DIR "/protocol/salient-sim");
    for (const char* opt : {"--log", "--stats"})
      args.push_back(opt), args.push_back((dir_ / (opt + 2)).string());
    int out[2];
    REQUIRE(::pipe(out) == 0);
    pid_ = ::fork();
    REQUIRE(pid_ >= 0);
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      ::close(out[0]);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      std::_Exit(127);
    }
    ::close(out[1]);
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') device_ += c;
    ::close(out[0]);
    REQUIRE(device_.rfind("/dev/pts/", 0) == 0);
  }
  ~Simulator() {
    stop();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  // Ends the simulator (it flushes its log and stats), once.
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  const std::string& device() const { return device_; }
  std::vector<std::string> log() const { return read_lines(dir_ / "log"); }
  long long stat(const std::string& key) const { return stat_of(dir_ / "stats", key); }

 private:
  pid_t pid_ = -1;
  fs::path dir_;
  std::string device_;
};

struct Run {
  serial::PrintResult result;
  std::vector<std::string> log;  // what the simulator executed
  long long lines_rejected = 0, oks_dropped = 0, lines_after_halt = 0;
};

Run print_through(const std::vector<std::string>& sim_args, const std::vector<std::string>& gcode,
                  milliseconds timeout, std::size_t resume_from = 0) {
  Simulator sim(sim_args);
  serial::LinkConfig config;
  config.session.reply_timeout = timeout;
  config.session.resend_ok_wait = milliseconds(50);
  serial::MarlinLink link(serial::open_serial({sim.device(), 250000, true, false}), config);
  link.handshake();
  Run run;
  run.result = link.print(std::make_shared<const Program>(Program::from_lines(gcode)), {}, resume_from);
  sim.stop();
  run.log = sim.log();
  run.lines_rejected = sim.stat("lines_rejected");
  run.oks_dropped = sim.stat("oks_dropped");
  run.lines_after_halt = sim.stat("lines_after_halt");
  return run;
}

// The log without the host's own commands: M115 (handshake), M110 N0, and exactly `pokes` M105s.
std::vector<std::string> printed(const Run& run) {
  std::vector<std::string> out;
  std::size_t pokes = 0;
  for (std::size_t i = 0; i < run.log.size(); ++i) {
    const std::string& c = run.log[i];
    if ((i == 0 && c == "M115") || (i == 1 && c == "M110 N0")) continue;
    if (c == "M105") {
      ++pokes;
      continue;
    }
    out.push_back(c);
  }
  CHECK(pokes == run.result.pokes);
  return out;
}

const std::vector<std::string>& big_file() {
  static const std::vector<std::string> g = make_gcode(50000);
  return g;
}

void check_exact(const std::vector<std::string>& sim_args, milliseconds timeout) {
  const auto& gcode = big_file();
  REQUIRE(gcode.size() >= 50000);
  const Run run = print_through(sim_args, gcode, timeout);
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.result.confirmed == run.result.total);
  const std::vector<std::string> expected = commands_of(gcode);
  const std::vector<std::string> got = printed(run);
  CHECK(got.size() == expected.size());
  CHECK(got == expected);  // none lost, none doubled, in order
  MESSAGE(run.result.total << " commands in " << run.result.seconds << " s, " << run.lines_rejected
                           << " lines rejected, " << run.result.lines_resent << " resent, " << run.oks_dropped
                           << " oks dropped, " << run.result.pokes << " pokes");
}

}  // namespace

TEST_CASE("ping-pong, no faults: the log is the file") {
  check_exact({}, milliseconds(2000));
}
TEST_CASE("ADVANCED_OK send-ahead, no faults: the log is the file") {
  check_exact({"--advanced-ok"}, milliseconds(2000));
}

TEST_CASE("noise 2 %: every corrupted line is asked for again and executed once") {
  check_exact({"--faults", "noise=0.02,seed=11"}, milliseconds(200));
  check_exact({"--advanced-ok", "--faults", "noise=0.02,seed=12"}, milliseconds(200));
}

TEST_CASE("lost oks: pokes (ping-pong) or the next ok's N (ADVANCED_OK) make up for them") {
  check_exact({"--faults", "drop-ok=0.01,seed=13"}, milliseconds(25));
  check_exact({"--advanced-ok", "--faults", "drop-ok=0.01,seed=14"}, milliseconds(25));
}

TEST_CASE("a firmware that sends no ok after Resend") {
  check_exact({"--faults", "resend-without-ok,noise=0.02,seed=15"}, milliseconds(200));
  check_exact({"--advanced-ok", "--faults", "resend-without-ok,noise=0.02,seed=16"}, milliseconds(200));
}

TEST_CASE("busy heating: the keepalives hold off the timeout, no poke is needed") {
  // Heating takes ~2 s of wall time; busy comes every 60 ms; the host would poke after 300 ms.
  const auto& gcode = big_file();
  const Run run = print_through({"--heat-time-scale", "0.03"}, gcode, milliseconds(300));
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.result.pokes == 0);
  CHECK(printed(run) == commands_of(gcode));
}

TEST_CASE("all faults at once, with heating, in both flow-control modes") {
  const std::string faults = "noise=0.02,drop-ok=0.01,resend-without-ok";
  check_exact({"--heat-time-scale", "0.02", "--faults", faults + ",seed=17"}, milliseconds(25));
  check_exact({"--advanced-ok", "--heat-time-scale", "0.02", "--faults", faults + ",seed=18"},
              milliseconds(25));
}

TEST_CASE("a disconnect ends the print with the last confirmed command, and resuming completes it") {
  const auto& gcode = big_file();
  const std::vector<std::string> all = commands_of(gcode);
  const Run cut =
      print_through({"--advanced-ok", "--faults", "disconnect-after=5000"}, gcode, milliseconds(500));
  CHECK(cut.result.disconnected);
  CHECK(cut.result.end == PrintEnd::failed);
  CHECK(cut.result.reason.find("disconnected") != std::string::npos);
  const std::vector<std::string> first = printed(cut);
  // 5000 executed including M115 and M110; what was confirmed was executed, in order.
  REQUIRE(first.size() == 4998);
  CHECK(std::vector<std::string>(all.begin(), all.begin() + 4998) == first);
  CHECK(cut.result.confirmed <= first.size());
  CHECK(cut.result.confirmed + 4 >= first.size());  // at most the lines in flight went unconfirmed
  // Resume on a fresh printer from the last confirmed command.
  const std::size_t from = cut.result.confirmed;
  const std::vector<std::string> prelude = marlin::resume_prelude(Program::from_lines(gcode), from);
  const Run rest =
      print_through({"--advanced-ok"}, gcode, milliseconds(500), from);  // the link adds the prelude
  CHECK(rest.result.end == PrintEnd::finished);
  std::vector<std::string> expected = prelude;
  const std::vector<std::string> tail = commands_of(gcode, from);
  expected.insert(expected.end(), tail.begin(), tail.end());
  CHECK(printed(rest) == expected);
}

TEST_CASE("a reset ends the print with a clear state and the last confirmed command") {
  const Run run = print_through({"--faults", "reset-after=3000"}, big_file(), milliseconds(500));
  CHECK(run.result.end == PrintEnd::failed);
  CHECK_FALSE(run.result.disconnected);
  CHECK(run.result.reason.find("restarted") != std::string::npos);
  // Executed: M115, M110 and 2998 of the file's commands; the last of them rebooted it before its ok.
  CHECK(run.result.confirmed == 2997);
}

TEST_CASE("thermal runaway stops sending at once") {
  const Run run = print_through({"--faults", "thermal-runaway-at=4000"}, big_file(), milliseconds(500));
  CHECK(run.result.end == PrintEnd::failed);
  CHECK(run.result.reason.find("Thermal Runaway") != std::string::npos);
  CHECK(run.log.size() == 4000);
  CHECK(run.lines_after_halt == 0);  // not a single line after the error
  const Run ahead =
      print_through({"--advanced-ok", "--faults", "thermal-runaway-at=4000"}, big_file(), milliseconds(500));
  CHECK(ahead.result.end == PrintEnd::failed);
  CHECK(ahead.lines_after_halt <= 3);  // only lines already on the wire when it halted (B ≤ 3)
}

TEST_CASE("the link reports a printer that does not answer, and a TCP address that refuses") {
  CHECK_THROWS_AS(serial::open_serial({"/dev/salient-no-such-port", 115200, true, false}), serial::LinkError);
  CHECK_THROWS_AS(serial::open_tcp("127.0.0.1:1"), serial::LinkError);
  CHECK_THROWS_AS(serial::open_tcp("no-port"), serial::LinkError);
}

TEST_CASE("the TCP transport (a ser2net-style bridge): the same print, exactly") {
  // A bridge on loopback with the simulated firmware behind it, in this process.
  const int listener = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(::bind(listener, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  REQUIRE(::listen(listener, 1) == 0);
  socklen_t len = sizeof a;
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&a), &len);
  std::atomic<bool> stop{false};
  std::vector<std::string> executed;
  std::thread bridge([&] {
    const int fd = ::accept(listener, nullptr, nullptr);
    sim::SimConfig config;
    config.advanced_ok = true;
    config.faults = sim::parse_faults("noise=0.02,seed=21");
    sim::SimFirmware fw(config);
    const auto t0 = std::chrono::steady_clock::now();
    auto now = [&] { return std::chrono::duration_cast<sim::Micros>(std::chrono::steady_clock::now() - t0); };
    char buf[65536];
    while (!stop) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 5) > 0) {
        const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
        if (n <= 0) break;
        fw.receive(std::string_view(buf, static_cast<std::size_t>(n)), now());
      }
      fw.advance(now());
      const std::string out = fw.take_output(now());
      if (!out.empty()) ::send(fd, out.data(), out.size(), MSG_NOSIGNAL);
      for (auto& c : fw.take_executed()) executed.push_back(std::move(c));
    }
    ::close(fd);
  });
  const std::vector<std::string> gcode = make_gcode(3000);
  serial::LinkConfig config;
  config.session.reply_timeout = milliseconds(200);
  serial::MarlinLink link(serial::open_tcp("127.0.0.1:" + std::to_string(ntohs(a.sin_port))), config);
  CHECK(link.handshake().name.find("salient-sim") != std::string::npos);
  Run run;
  run.result = link.print(std::make_shared<const Program>(Program::from_lines(gcode)));
  stop = true;
  bridge.join();
  ::close(listener);
  run.log = executed;
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.result.lines_resent > 0);  // the noise was there, and was got over
  CHECK(printed(run) == commands_of(gcode));
}
