// The s3g link end to end: S3gLink over our Asio serial transport, to `salient-sim --firmware
// sailfish` on a real pseudo-terminal, printing a real .x3g (GPX writes it from slicer-shaped
// G-code at test time). The simulator logs each action it executed; the log must be the file's
// actions exactly once, in order, under every fault. Skipped without gpx.
#include "protocol/serial/s3g_link.hpp"

#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "protocol/s3g/x3g_program.hpp"

namespace fs = std::filesystem;
using namespace salient::protocol;
using std::chrono::milliseconds;

namespace {

// salient-sim (SALIENT_SIM overrides the build's, to try another build of it).
std::string sim_path() {
  if (const char* p = std::getenv("SALIENT_SIM")) return p;
  return SALIENT_BINARY_DIR "/protocol/salient-sim";
}

// gpx writes the x3g; the simulator must have the Sailfish board (--firmware sailfish).
bool ready() {
  static const bool ok = [] {
    if (std::system("command -v gpx > /dev/null 2>&1") != 0) {
      MESSAGE("gpx is not installed: the s3g link tests are skipped");
      return false;
    }
    const std::string cmd = "'" + sim_path() + "' --help 2>/dev/null | grep -q 'firmware.*sailfish'";
    if (std::system(cmd.c_str()) != 0) {
      MESSAGE("salient-sim has no --firmware sailfish: the s3g link tests are skipped");
      return false;
    }
    return true;
  }();
  return ok;
}

// A print as a slicer writes it for the Replicator: heat-up, homing, layers of moves.
std::string make_gcode(std::size_t moves) {
  std::ostringstream g;
  g << "; generated for the s3g link tests\nM73 P0\nM140 S60 T0\nM104 S210 T0\nG162 X Y F2500\nG161 Z F1100\n"
       "G92 X152 Y75 Z0 A0 B0\nM190 S60 T0\nM109 S210 T0\nG90\nG1 Z0.3 F1000\n";
  char buf[96];
  double e = 0;
  for (std::size_t i = 0, layer = 0; i < moves; ++i) {
    if (i % 500 == 0) {
      std::snprintf(buf, sizeof buf, ";LAYER_CHANGE\nG1 Z%.2f F1000\n", 0.3 + 0.2 * double(layer++));
      g << buf;
    }
    const double a = double(i % 500) * 0.0125;
    e += 0.02 + 1e-5 * double(i % 97);
    std::snprintf(buf, sizeof buf, "G1 X%.3f Y%.3f E%.5f F%d\n", 30 * std::cos(a), 30 * std::sin(a), e,
                  i % 50 == 0 ? 1800 : 3000);
    g << buf;
  }
  g << "M73 P100\nM104 S0 T0\nM140 S0 T0\nM18\n";
  return g.str();
}

fs::path test_dir() {
  static int counter = 0;
  const fs::path d = fs::temp_directory_path() / ("salient-s3g-link-test-" + std::to_string(::getpid()) +
                                                  "-" + std::to_string(counter++));
  fs::create_directories(d);
  return d;
}

// GPX's x3g for `moves` moves, made once per size.
std::shared_ptr<const s3g::X3gProgram> x3g_of(std::size_t moves) {
  static std::map<std::size_t, std::shared_ptr<const s3g::X3gProgram>> made;
  if (auto it = made.find(moves); it != made.end()) return it->second;
  const fs::path d = test_dir();
  std::ofstream(d / "p.gcode") << make_gcode(moves);
  const std::string cmd =
      "gpx -I -q -m r2x '" + (d / "p.gcode").string() + "' '" + (d / "p.x3g").string() + "'";
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::ifstream in(d / "p.x3g", std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  auto p = std::make_shared<const s3g::X3gProgram>(s3g::X3gProgram::from_x3g(s.str()));
  fs::remove_all(d);
  return made[moves] = p;
}

std::string hex(const std::string& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned char c : bytes) out += digits[c >> 4], out += digits[c & 15];
  return out;
}

std::vector<std::string> hex_of(const std::vector<std::string>& actions, std::size_t from = 0) {
  std::vector<std::string> out;
  for (std::size_t i = from; i < actions.size(); ++i) out.push_back(hex(actions[i]));
  return out;
}

std::vector<std::string> read_lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// salient-sim --firmware sailfish as a child process, on its own pseudo-terminal.
class Board {
 public:
  explicit Board(std::vector<std::string> args) : dir_(test_dir()) {
    args.insert(args.begin(), {sim_path(), "--firmware", "sailfish", "--log", (dir_ / "log").string(),
                               "--stats", (dir_ / "stats").string()});
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
  ~Board() {
    stop();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  const std::string& device() const { return device_; }
  std::vector<std::string> log() const { return read_lines(dir_ / "log"); }

 private:
  fs::path dir_;
  pid_t pid_ = -1;
  std::string device_;
};

serial::S3gLinkConfig quick_config() {
  serial::S3gLinkConfig c;
  // The simulator answers in well under a millisecond; a packet whose length byte noise made
  // longer is answered 8C after 200 ms.
  c.session.reply_timeout = milliseconds(250);
  c.session.byte_timeout = milliseconds(30);
  c.session.silence_limit = milliseconds(5000);
  return c;
}

struct Run {
  serial::PrintResult result;
  std::vector<std::string> log;
  std::string firmware;
};

// Prints `program` to a fresh board; `during` runs on another thread while it prints.
Run print_to(const std::vector<std::string>& sim_args, std::shared_ptr<const s3g::X3gProgram> program,
             std::size_t resume_from = 0, const std::function<void(serial::S3gLink&)>& during = {}) {
  Board board(sim_args);
  serial::S3gLink link(serial::open_serial({board.device(), 115200, true, false}), quick_config());
  Run run;
  run.firmware = link.handshake().name;
  std::thread side;
  if (during) side = std::thread([&] { during(link); });
  run.result = link.print_x3g(std::move(program), {}, resume_from, {});
  if (side.joinable()) side.join();
  std::this_thread::sleep_for(milliseconds(300));  // what was acked runs out of the ring
  board.stop();
  run.log = board.log();
  return run;
}

const std::vector<std::string> kFast = {"--time-scale", "0.0001", "--heat-time-scale", "0.001"};

std::vector<std::string> with(std::vector<std::string> a, const std::string& faults) {
  a.push_back("--faults"), a.push_back(faults);
  return a;
}

}  // namespace

TEST_CASE("s3g link: a GPX x3g prints to the simulated Sailfish board exactly once, in order") {
  if (!ready()) return;
  const auto p = x3g_of(3000);
  const Run run = print_to(kFast, p);
  CHECK(run.firmware == "Sailfish 7.7");
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.result.confirmed == p->commands);
  CHECK(run.log == hex_of(p->actions));
}

TEST_CASE(
    "s3g link: 50,000 actions under corruption both ways, lost replies and buffer-full storms, every action "
    "once") {
  if (!ready()) return;
  const auto p = x3g_of(50000);
  REQUIRE(p->actions.size() >= 50000);
  const Run run =
      print_to(with(kFast, "noise=0.02,reply-noise=0.02,drop-reply=0.002,full-storm=0.01,seed=3"), p);
  INFO(run.result.reason);
  MESSAGE("resent ", run.result.lines_resent, " timeouts ", run.result.pokes, " seconds ",
          run.result.seconds);
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.result.lines_resent > 100);
  CHECK(run.log.size() == p->actions.size());
  CHECK(run.log == hex_of(p->actions));
}

TEST_CASE("s3g link: a reset mid-print is reported and resumable from what had started") {
  if (!ready()) return;
  const auto p = x3g_of(3000);
  // Slow enough that build stats (~1/s) see the line move before the reset.
  const Run run = print_to(with({"--time-scale", "0.1", "--heat-time-scale", "0.001"}, "reset-at=1500"), p);
  CHECK(run.result.end == PrintEnd::failed);
  CHECK(run.result.reason == "the printer reset");
  const std::size_t resume = run.result.confirmed;
  CHECK(resume <= 1500);
  CHECK(resume > 0);
  REQUIRE(run.log.size() >= 1500);
  const auto want = hex_of(p->actions);
  CHECK(std::vector<std::string>(run.log.begin(), run.log.begin() + 1500) ==
        std::vector<std::string>(want.begin(), want.begin() + 1500));
  // A fresh board from there: the rest, exactly.
  const Run rest = print_to(kFast, p, resume);
  CHECK(rest.result.end == PrintEnd::finished);
  CHECK(rest.log == hex_of(p->actions, p->first_action_of(resume)));
}

TEST_CASE("s3g link: 89 (cancelled on the LCD) and 8B (heater shutdown) stop the print with their reason") {
  if (!ready()) return;
  const auto p = x3g_of(3000);
  const Run lcd = print_to(with(kFast, "cancel-at=800"), p);
  CHECK(lcd.result.end == PrintEnd::cancelled);
  CHECK(lcd.result.reason == "build cancelled on the printer");
  const Run hot = print_to(with(kFast, "heater-fault-at=800"), p);
  CHECK(hot.result.end == PrintEnd::failed);
  CHECK(hot.result.reason == "heater shutdown (a heater fault)");
  CHECK(hot.log.size() < p->actions.size());
}

TEST_CASE("s3g link: cancel mid-print aborts, then heaters and motors off") {
  if (!ready()) return;
  const auto p = x3g_of(20000);
  const Run run =
      print_to({"--time-scale", "0.01", "--heat-time-scale", "0.001"}, p, 0, [](serial::S3gLink& l) {
        std::this_thread::sleep_for(milliseconds(1500));
        l.cancel();
      });
  CHECK(run.result.end == PrintEnd::cancelled);
  REQUIRE(run.log.size() >= 3);
  const std::size_t n = run.log.size();
  CHECK(run.log[n - 3] == "880003020000");
  CHECK(run.log[n - 2] == "88001f020000");
  CHECK(run.log[n - 1] == "891f");
  const auto want = hex_of(p->actions);
  CHECK(std::vector<std::string>(run.log.begin(), run.log.end() - 3) ==
        std::vector<std::string>(want.begin(), want.begin() + static_cast<long>(n - 3)));
}

TEST_CASE("s3g link: pause and resume mid-print, the log still exact") {
  if (!ready()) return;
  const auto p = x3g_of(3000);
  const Run run =
      print_to({"--time-scale", "0.02", "--heat-time-scale", "0.001"}, p, 0, [](serial::S3gLink& l) {
        std::this_thread::sleep_for(milliseconds(800));
        l.pause();
        std::this_thread::sleep_for(milliseconds(1000));
        l.resume();
      });
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.log == hex_of(p->actions));
}

TEST_CASE("s3g link: a board that meets noise with silence (as Sailfish 7.7 does), every action once") {
  if (!ready()) return;
  const auto p = x3g_of(3000);
  std::vector<std::string> args = with(kFast, "noise=0.01,reply-noise=0.01,seed=4");
  args.push_back("--quiet-errors");
  const Run run = print_to(args, p);
  INFO(run.result.reason);
  CHECK(run.result.end == PrintEnd::finished);
  CHECK(run.result.pokes > 10);  // the noise cost timeouts, not error replies
  CHECK(run.log == hex_of(p->actions));
}

TEST_CASE("s3g link: cancel while paused still turns the heaters and motors off") {
  if (!ready()) return;
  const auto p = x3g_of(20000);
  const Run run =
      print_to({"--time-scale", "0.01", "--heat-time-scale", "0.001"}, p, 0, [](serial::S3gLink& l) {
        std::this_thread::sleep_for(milliseconds(1000));
        l.pause();
        std::this_thread::sleep_for(milliseconds(800));
        l.cancel();
      });
  CHECK(run.result.end == PrintEnd::cancelled);
  REQUIRE(run.log.size() >= 3);
  const std::size_t n = run.log.size();
  CHECK(run.log[n - 3] == "880003020000");
  CHECK(run.log[n - 2] == "88001f020000");
  CHECK(run.log[n - 1] == "891f");
}
