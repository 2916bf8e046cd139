// `salient doctor`: what to run when "it does not connect". Each check is one line: ok, warn or
// fail, what was found, and for anything not ok the fix. The checks look at this machine (serial
// devices, permissions, ModemManager and brltty, ports held by other processes, disk space) and
// at the daemon (reachable, the key, its printers, its clock).
#pragma once

#include <string>
#include <vector>

namespace salient::cli::doctor {

enum class Verdict { ok, warn, fail };

struct Check {
  Verdict verdict = Verdict::ok;
  std::string name;   // "serial", "key", …
  std::string found;  // what was seen
  std::string fix;    // what to do (empty when ok)
};

struct Options {
  std::string server, key;           // as the client commands take them
  std::vector<std::string> devices;  // extra device paths (a printer's configured port)
  std::string data_dir;              // for the disk check; empty: /var/lib/salient or ./var
};

// doctor_serial.cpp: devices present (with their /dev/serial/by-id names), whether this user can
// open them, who else holds them, and the services known to grab new serial devices.
std::vector<Check> serial_checks(const std::vector<std::string>& extra_devices);
std::vector<Check> interference_checks();
// doctor_daemon.cpp: reachable, the key accepted, each printer's state, the clock.
std::vector<Check> daemon_checks(const Options& options);
// doctor_command.cpp: free space where the data directory is.
Check disk_check(const std::string& data_dir);
// The data directory the checks look at: `option`, else the installed daemon's (/var/lib/salient),
// else a checkout's (./var); empty when there is none.
std::string find_data_dir(const std::string& option);

// A process by pid and name (/proc/PID/comm), for the checks that look at other processes.
struct Process {
  int pid = 0;
  std::string name;
};
std::vector<Process> processes();

}  // namespace salient::cli::doctor
