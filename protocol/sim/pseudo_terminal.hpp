// PseudoTerminal: the printer's end of a pseudo-terminal. Hosts open device_path() as they would
// open /dev/ttyACM0. We keep a descriptor on that end too, raw, so that the link survives a host
// closing and reopening it; close() pulls the cable: the host's reads fail at once.
// A pseudo-terminal has no DTR line, so watch_opens() tells the host's opens by inotify instead.
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
  // Drops what we wrote that the host has not read yet; throws std::system_error.
  void discard_output();
  // From now on, counts the host's opens of the device; throws std::system_error.
  void watch_opens();
  int watch_descriptor() const { return watch_; }  // readable when the host opened it; -1: not watching
  int take_opens();                                // opens since the last call
  void close();

 private:
  int master_ = -1, slave_ = -1, watch_ = -1;
  std::string path_;
};

}  // namespace salient::protocol::sim
