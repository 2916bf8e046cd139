#include "server/printers/sim_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace salient::server {

namespace fs = std::filesystem;

std::string find_sim_program() {
  if (const char* env = std::getenv("SALIENT_SIM"); env && *env) return env;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const fs::path& candidate :
         {self.parent_path() / "salient-sim", self.parent_path().parent_path() / "protocol" / "salient-sim"})
      if (fs::exists(candidate, ec)) return candidate.string();
  }
  return "salient-sim";
}

std::vector<std::string> split_args(const std::string& text) {
  std::vector<std::string> out;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (char c : text) {
    if (quote) {
      if (c == quote)
        quote = 0;
      else
        word += c;
    } else if (c == '\'' || c == '"') {
      quote = c, in_word = true;
    } else if (c == ' ' || c == '\t' || c == '\n') {
      if (in_word) out.push_back(word), word.clear(), in_word = false;
    } else {
      word += c, in_word = true;
    }
  }
  if (quote) throw std::invalid_argument("unclosed quote in '" + text + "'");
  if (in_word) out.push_back(word);
  return out;
}

SimProcess::SimProcess(const std::string& program, const std::vector<std::string>& args) {
  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe: cannot start " + program);
  std::vector<std::string> argv_text{program};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ == 0) {
    // The child, until exec: async-signal-safe calls only. It dies with the daemon, even a
    // kill -9'd one, so that no simulator is left holding a pseudo-terminal.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    dup2(out[1], STDOUT_FILENO);
    const int null = open("/dev/null", O_RDONLY);
    if (null >= 0) dup2(null, STDIN_FILENO);
    // Nothing of the daemon's (its listening socket, clients, database) may live on in the
    // simulator: a descriptor opened without O_CLOEXEC anywhere would hold the port after a kill -9.
    if (syscall(SYS_close_range, 3U, ~0U, 0U) != 0)
      for (int fd = 3; fd < 65536; ++fd) close(fd);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);  // the daemon blocks SIGTERM in its threads
    execvp(argv[0], argv.data());
    _exit(127);
  }
  const int spawn_error = pid_ < 0 ? errno : 0;
  close(out[1]);
  if (pid_ < 0) {
    close(out[0]);
    throw std::runtime_error("cannot start " + program + ": " + std::strerror(spawn_error));
  }
  // Its first line is the device path.
  std::string line;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (line.find('\n') == std::string::npos && std::chrono::steady_clock::now() < until) {
    pollfd p{out[0], POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    char buf[256];
    const ssize_t n = read(out[0], buf, sizeof buf);
    if (n <= 0) break;
    line.append(buf, static_cast<std::size_t>(n));
  }
  close(out[0]);  // later output (none expected) would get SIGPIPE; the simulator logs to stderr
  const std::size_t nl = line.find('\n');
  if (nl == std::string::npos || line.rfind("/dev/", 0) != 0) {
    stop();
    throw std::runtime_error(program +
                             " did not report a device: is salient-sim built, and are its sim_args right? "
                             "(see salientd's log; SALIENT_SIM names the program)");
  }
  device_ = line.substr(0, nl);
}

SimProcess::~SimProcess() {
  stop();
}

bool SimProcess::running() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    pid_ = -1;
    return false;
  }
  return true;
}

void SimProcess::stop() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  int status = 0;
  for (int i = 0; i < 50; ++i) {
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, &status, 0);
  pid_ = -1;
}

}  // namespace salient::server
