// SimProcess: a salient-sim child on a pseudo-terminal, for a printer of kind "sim". It is started
// with the printer's sim_args, its device path read from its first line of output, and it is
// stopped (SIGTERM, then SIGKILL) when this object goes.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace salient::server {

class SimProcess {
 public:
  // Throws std::runtime_error when the program cannot start or does not report a device.
  SimProcess(const std::string& program, const std::vector<std::string>& args);
  ~SimProcess();
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  const std::string& device() const { return device_; }
  pid_t pid() const { return pid_; }
  bool running();

 private:
  void stop();
  pid_t pid_ = -1;
  std::string device_;
};

// Where salient-sim is: $SALIENT_SIM, next to this executable, in the build tree beside it
// (../protocol/), or on PATH.
std::string find_sim_program();
// "--time-scale 0.02 --log 'a b'" → words (single and double quotes group).
std::vector<std::string> split_args(const std::string& text);

}  // namespace salient::server
