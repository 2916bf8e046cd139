// PseudoTerminal: the printer's end of a pseudo-terminal. Hosts open device_path() as they would
// open /dev/ttyACM0. We keep a descriptor on that end too, raw, so that the link survives a host
// closing and reopening it; close() pulls the cable: the host's reads fail at once.
#pragma once

#include <string>
#include <string_view>

namespace salient::protocol::sim {

class PseudoTerminal {
 public:
  PseudoTerminal();  // throws std::system_error
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  const std::string& device_path() const { return path_; }
  int descriptor() const { return master_; }  // non-blocking
  // Bytes written by the host so far (may be empty); throws std::system_error.
  std::string read_available();
  // Writes what it can without blocking; returns how many bytes went.
  std::size_t write_some(std::string_view bytes);
  void close();

 private:
  int master_ = -1, slave_ = -1;
  std::string path_;
};

}  // namespace salient::protocol::sim
